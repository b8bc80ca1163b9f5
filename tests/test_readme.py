"""The README's Python example runs as written (output paths redirected)."""

import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_python_example_runs(tmp_path, capsys):
    code = re.search(r"```python\n(.*?)```", README.read_text(), re.S).group(1)
    assert 'out="runs/frc"' in code
    code = code.replace('out="runs/frc"', f'out="{tmp_path / "frc"}"')
    exec(compile(code, str(README), "exec"), {"__name__": "readme"})
    out = capsys.readouterr().out.split("\n")
    assert out[1].startswith("periodic")
    assert out[2].startswith("complete")
    assert (tmp_path / "frc" / "frc.nc").exists()
