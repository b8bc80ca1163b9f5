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


def _commands() -> list[str]:
    """The README's command lines (indented ``jointdyn ...`` lines), comments dropped."""
    lines = re.findall(r"^ {4}(jointdyn .*|pip .*|python .*)$", README.read_text(), re.M)
    return [line.split("#", 1)[0].strip() for line in lines]


def test_readme_command_inputs_exist():
    """Every file a README command reads is where the command says (from the
    repository root, where the Set-up section runs them)."""
    root = README.parent
    commands = _commands()
    assert any("--input" in c for c in commands) and any("--system" in c for c in commands)
    missing = []
    for command in commands:
        for path in re.findall(r"--(?:input|system) (\S+)", command):
            if not (root / path).is_file():
                missing.append(f"{command}: {path}")
    assert not missing, missing


def test_gitignore_covers_what_the_readme_writes():
    """The folders the README's commands and example write are ignored by git."""
    import shutil
    import subprocess

    import pytest

    root = README.parent
    text = README.read_text()
    outputs = {p for c in _commands() for p in re.findall(r"--out (\S+)", c)}
    outputs |= set(re.findall(r'out="([^"]+)"', text))
    outputs |= {"docs/_build/html"} if "docs/_build/html" in text else set()
    assert {"run/", "figures-out", "runs/frc"} <= outputs
    git = shutil.which("git")
    if not git or not (root / ".git").exists():
        pytest.skip("not a git checkout")
    probes = [str(Path(p) / "probe.txt") for p in sorted(outputs)]
    proc = subprocess.run([git, "check-ignore", "--no-index", *probes], cwd=root, capture_output=True, text=True)
    ignored = set(proc.stdout.split())
    assert set(probes) <= ignored, f"not ignored: {sorted(set(probes) - ignored)}"


def test_performance_page_gives_what_the_readme_promises():
    """The README sends readers to docs/performance.md for install, first-run and test-suite times: the
    page has them (outside the part its script rewrites)."""
    text = README.read_text()
    assert "docs/performance.md#install-first-run-and-test-suite" in text
    page = (README.parent / "docs" / "performance.md").read_text()
    head, _, _ = page.partition("<!-- performance:begin -->")
    assert "## Install, first run and test suite" in head
    rows = [line for line in head.splitlines() if line.startswith("| ")]
    assert any(r.startswith("| install") for r in rows) and any(r.startswith("| first run") for r in rows)
    assert re.search(r"\*\*Test suite\*\*.*?\d+ passed.*?\d+ s", head, re.S)  # a measured count and time
