"""Write the result tables of the README and docs/ (index, results, held-out) from the stored
study results in docs/results/ (issue 31, item 5): numbers come from results, not typing.

Every generated table sits between two markers on its page::

    <!-- generated: NAME (studies/publish_tables.py) -->
    | … the table … |
    <!-- end generated -->

and this script rewrites what is between them from the study folders under docs/results/
(each a `dcee report` ``metrics.csv``, optionally a ``paired.csv``, and a README that says
where it came from). ``--check`` rewrites nothing and exits 1 naming every table that
disagrees with its results (tests/test_published_numbers.py runs it).

    python studies/publish_tables.py           # rewrite the tables
    python studies/publish_tables.py --check   # exit 1 if a page disagrees with its results
    bash studies/run.sh publish                # the same as the first
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:  # run as a script: the studies package sits beside it
    sys.path.insert(0, str(ROOT))

from studies.tables import TABLES  # noqa: E402

PAGES = (
    "README.md",
    "docs/index.md",
    "docs/results.md",
    "docs/held-out.md",
    "docs/scenarios.md",
    "docs/plumes.md",
    "docs/performance.md",
    "docs/multi-source.md",
    "docs/three-d.md",
    "docs/guide/robot.md",
    "docs/guide/on-a-map.md",
)
MARKER = re.compile(
    r"(<!-- generated: (?P<name>[a-z0-9-]+) \(studies/publish_tables\.py\) -->\n)"
    r"(?P<body>.*?)"
    r"(<!-- end generated -->)",
    re.DOTALL,
)


def render(text: str) -> tuple[str, list[str]]:
    """``text`` with every generated region rewritten, and the names of those that changed."""
    changed: list[str] = []

    def one(m: re.Match[str]) -> str:
        name = m.group("name")
        if name not in TABLES:
            raise KeyError(f"unknown generated table {name!r} (studies/publish_tables.py)")
        body = TABLES[name]()
        if body != m.group("body"):
            changed.append(name)
        return m.group(1) + body + m.group(4)

    return MARKER.sub(one, text), changed


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true", help="exit 1 if a page disagrees")
    args = ap.parse_args(argv)
    stale = []
    for page in PAGES:
        path = ROOT / page
        text = path.read_text(encoding="utf-8")
        new, changed = render(text)
        stale += [f"{page}: {name}" for name in changed]
        if changed and not args.check:
            path.write_text(new, encoding="utf-8")
    if args.check and stale:
        print("pages disagree with the stored results (run python studies/publish_tables.py):")
        print("\n".join(f"  {s}" for s in stale))
        return 1
    print(("checked" if args.check else "wrote") + f" the generated tables of {', '.join(PAGES)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
