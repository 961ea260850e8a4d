"""Files from others read without trust: the fuzz benchmark of every reader (issue 80)."""

from __future__ import annotations

import json

from studies.tables.common import RESULTS, table

FOLDER = RESULTS / "fuzz"


def fuzz_readers_table() -> str:
    """Per format: the corrupted cases run, how many were read and refused (one line), and how
    many failed (another exception, several lines, no answer in 30 s)."""
    doc = json.loads((FOLDER / "readers.json").read_text(encoding="utf-8"))
    machine = doc["machine"]
    commit = str(doc["code_version"].get("commit", ""))[:9]
    rows = [
        [
            r["format"],
            str(r["cases"]),
            str(r["read"]),
            str(r["refused"]),
            str(len(r["failures"])),
            f"{r['seconds']:.0f}",
        ]
        for r in doc["formats"]
    ]
    rows.append(
        [
            f"all ({machine['processor'] or machine['machine']}, code {commit})",
            str(sum(r["cases"] for r in doc["formats"])),
            str(sum(r["read"] for r in doc["formats"])),
            str(sum(r["refused"] for r in doc["formats"])),
            str(sum(len(r["failures"]) for r in doc["formats"])),
            f"{sum(r['seconds'] for r in doc['formats']):.0f}",
        ]
    )
    return table(["format", "cases", "read", "refused (one line)", "failed", "seconds"], rows)
