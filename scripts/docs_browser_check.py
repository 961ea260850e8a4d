"""Look at the built documentation site in a real browser (headless Chromium, network off):
every page with equations must show typeset math (KaTeX output, no raw TeX left), and no page
may log a JavaScript error to the console. Screenshots of the checked pages go to the output
folder. Skipped, with a note, where no Chromium is installed (it is not a Python package).

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

PAGES = ("dual-control/", "results/", "index.html", "design/")
BLOCK_NETWORK = "MAP * ~NOTFOUND , EXCLUDE localhost"


class QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, format: str, *args: object) -> None:
        pass


def chromium() -> str | None:
    return next(
        (p for n in ("chromium", "chromium-browser", "google-chrome") if (p := shutil.which(n))),
        None,
    )


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("site", type=Path)
    ap.add_argument("--shots", type=Path, default=None)
    args = ap.parse_args()
    browser = chromium()
    if browser is None:
        print("docs browser check: skipped (no Chromium here; e.g. apt install chromium)")
        return 0
    handler = functools.partial(QuietHandler, directory=str(args.site))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    base = f"http://localhost:{server.server_address[1]}/"
    flags = [
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        f"--host-resolver-rules={BLOCK_NETWORK}",
        "--virtual-time-budget=8000",
        "--enable-logging=stderr",
        "--v=0",
    ]
    failures = []
    for page in PAGES:
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
        print(f"{page}: {math} equations, {typeset} typeset, {raw} raw, {len(errors)} errors")
        if errors:
            failures.append(f"{page}: console: {errors[0]}")
        if math and (raw or typeset < math):
            failures.append(f"{page}: {raw} of {math} equations not typeset")
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
