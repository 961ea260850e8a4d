"""Look at the built documentation site in a real browser (headless Chromium, network off):
every page that holds an equation, and the home page, must show typeset math (KaTeX output, no
raw TeX left, no KaTeX error) and log no JavaScript error to the console. Screenshots of the
checked pages go to ``--shots``. Fails where no Chromium is installed (it is not a Python
package; ``scripts/setup-browser.sh`` installs Debian's): a check that skips itself is no check.

    .venv/bin/python scripts/docs_browser_check.py SITE_DIR [--shots DIR]
"""

from __future__ import annotations

import argparse
import functools
import http.server
import re
import shutil
import subprocess
import sys
import threading
from pathlib import Path

ALWAYS = ("index.html",)
BLOCK_NETWORK = "MAP * ~NOTFOUND , EXCLUDE localhost"


class QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, format: str, *args: object) -> None:
        pass


def chromium() -> str | None:
    return next(
        (p for n in ("chromium", "chromium-browser", "google-chrome") if (p := shutil.which(n))),
        None,
    )


def pages(site: Path) -> list[str]:
    """The pages to look at, as paths below the site's root: the home page and every page
    whose HTML holds an equation (Arithmatex's markup)."""
    found = sorted(
        str(p.relative_to(site))
        for p in site.rglob("*.html")
        if 'class="arithmatex"' in p.read_text(encoding="utf-8", errors="replace")
    )
    return [*ALWAYS, *(p for p in found if p not in ALWAYS)]


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("site", type=Path)
    ap.add_argument("--shots", type=Path, default=None)
    args = ap.parse_args()
    browser = chromium()
    if browser is None:
        print("docs browser check: no Chromium (bash scripts/setup-browser.sh)", file=sys.stderr)
        return 2
    handler = functools.partial(QuietHandler, directory=str(args.site))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    base = f"http://localhost:{server.server_address[1]}/"
    flags = [
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        # no calls home: this machine's closed network refuses them, many at a time
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--no-first-run",
        f"--host-resolver-rules={BLOCK_NETWORK}",
        "--virtual-time-budget=8000",
        "--enable-logging=stderr",
        "--v=0",
    ]
    failures = []
    for page in pages(args.site):
        url = base + page
        dom = subprocess.run(
            [browser, *flags, "--dump-dom", url], capture_output=True, text=True, timeout=120
        )
        errors = [
            line
            for line in dom.stderr.splitlines()
            if "CONSOLE" in line and re.search(r"Uncaught|Error|Failed to load", line)
        ]
        math = dom.stdout.count('class="arithmatex"')
        typeset = dom.stdout.count('class="katex"')
        raw = len(re.findall(r'class="arithmatex">\\[(\[]', dom.stdout))
        katex_errors = dom.stdout.count('class="katex-error"')
        print(f"{page}: {math} equations, {typeset} typeset, {raw} raw, {len(errors)} errors")
        if errors:
            failures.append(f"{page}: console: {errors[0]}")
        if math and (raw or typeset < math):
            failures.append(f"{page}: {raw} of {math} equations not typeset")
        if katex_errors:
            failures.append(f"{page}: {katex_errors} equations with a KaTeX error")
        if args.shots is not None:
            args.shots.mkdir(parents=True, exist_ok=True)
            shot = args.shots / (page.strip("/").replace("/", "-").replace(".html", "") + ".png")
            subprocess.run(
                [browser, *flags, "--hide-scrollbars", "--window-size=1280,1700",
                 f"--screenshot={shot}", url],
                capture_output=True, timeout=120,
            )  # fmt: skip
    server.shutdown()
    for f in failures:
        print(f"docs browser check: {f}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
