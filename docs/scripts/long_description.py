"""Write the package index's long description from README.md.

Usage::

    python docs/scripts/long_description.py           # rewrites docs/long-description.md
    python docs/scripts/long_description.py --check   # exit 1 if it is out of date

README.md is written for the repository view: it shows pictures and links to
pages of the repository by relative paths, which a package index cannot
resolve (there is no public address to make them absolute). The long
description is README.md without its pictures, with every relative link
turned into plain text that names the file. ``tests/test_packaging.py``
checks that the file in the repository is what this script writes.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
TARGET = ROOT / "docs" / "long-description.md"

_IMAGE = re.compile(r"^\s*!\[[^\]]*\]\([^)]*\)\s*$")
_LINK = re.compile(r"\[([^\]]+)\]\(([^)]+)\)")
_NOTE = ("<!-- Generated from README.md by docs/scripts/long_description.py; "
         "edit README.md and rerun the script. -->\n")


def _unlink(match: re.Match) -> str:
    text, target = match.group(1), match.group(2)
    if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # absolute address: keep the link
        return match.group(0)
    return text if f"`{target}`" in text or target in text else f"{text} (`{target}` in the source distribution)"


def long_description(readme: str) -> str:
    """README text without image lines and with relative links as plain text."""
    lines, fence = [], False
    for line in readme.splitlines():
        if line.lstrip().startswith("```"):
            fence = not fence
        if not fence:
            if _IMAGE.match(line):
                continue
            line = _LINK.sub(_unlink, line)
        lines.append(line)
    text = "\n".join(lines)
    text = re.sub(r"\n{3,}", "\n\n", text).strip() + "\n"
    return _NOTE + text


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    want = long_description(README.read_text(encoding="utf-8"))
    if "--check" in argv:
        have = TARGET.read_text(encoding="utf-8") if TARGET.exists() else ""
        if have != want:
            print(f"{TARGET.relative_to(ROOT)} is out of date: run python docs/scripts/long_description.py",
                  file=sys.stderr)
            return 1
        return 0
    TARGET.write_text(want, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
