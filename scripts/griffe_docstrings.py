"""A Griffe extension for the API reference (mkdocs.yml): dcee's docstrings use Sphinx-style
roles (``:func:`~dcee.runs.run_episode```), double-backtick literals and ``::`` literal blocks;
rendered as Markdown these show raw roles and turn code into block quotes. This rewrites them at
build time: a role becomes inline code (the short name for ``~``), a double-backtick literal
single backticks, a ``::`` block a fenced Python block and a doctest a fenced console block."""

from __future__ import annotations

import re
import textwrap
from typing import Any

import griffe

ROLE = re.compile(r":(?:py:)?(?:func|class|meth|attr|data|mod|obj|exc|const):`(~?)([^`]+)`")
LITERAL = re.compile(r"``([^`]+)``")


def markdown(doc: str) -> str:
    """The docstring with roles, literals and literal blocks in Markdown."""
    doc = ROLE.sub(lambda m: f"`{m.group(2).split('.')[-1] if m.group(1) else m.group(2)}`", doc)
    doc = LITERAL.sub(r"`\1`", doc)
    lines = doc.split("\n")
    out: list[str] = []
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.rstrip().endswith("::") and i + 1 < len(lines) and not lines[i + 1].strip():
            j = i + 2
            block: list[str] = []
            while j < len(lines) and (not lines[j].strip() or lines[j].startswith((" ", "\t"))):
                block.append(lines[j])
                j += 1
            while block and not block[-1].strip():
                block.pop()
            if block:
                stripped = line.rstrip()[:-2].rstrip()
                out += [stripped + ":" if stripped else "", "", "```python"]
                out += textwrap.dedent("\n".join(block)).split("\n")
                out += ["```", ""]
                i = j
                continue
        if line.lstrip().startswith(">>>"):  # a doctest: a fenced console block, not a quote
            j = i
            while j < len(lines) and lines[j].strip():
                j += 1
            out += ["```pycon", *textwrap.dedent("\n".join(lines[i:j])).split("\n"), "```"]
            i = j
            continue
        out.append(line)
        i += 1
    return "\n".join(out)


class DceeDocstrings(griffe.Extension):
    """Rewrite every docstring of the loaded package (see the module docstring)."""

    def on_object(self, *, obj: griffe.Object, **kwargs: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = markdown(obj.docstring.value)
