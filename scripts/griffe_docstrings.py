"""A Griffe extension for the API reference (mkdocs.yml): dcee's docstrings use Sphinx-style
roles (``:func:`~dcee.runs.run_episode```), double-backtick literals and ``::`` literal blocks;
rendered as Markdown these show raw roles and turn code into block quotes. This rewrites them at
build time: a role becomes a cross-reference (an autorefs link, ``[`run_episode`][dcee.runs.
episode.run_episode]``) when its target is an object the API pages document, else inline code
(the short name for ``~``); a double-backtick literal becomes single backticks, a ``::`` block
a fenced Python block and a doctest a fenced console block. Targets resolve as Python names
would: relative to the object's class, then its module, then its package, then ``dcee``;
names re-exported by a package resolve to where they are defined."""

from __future__ import annotations

import re
import textwrap
from pathlib import Path
from typing import Any

import griffe

ROLE = re.compile(r":(?:py:)?(?:func|class|meth|attr|data|mod|obj|exc|const):`(~?)([^`]+)`")
LITERAL = re.compile(r"``([^`]+)``")


API_PAGES = Path("docs/reference/api")
DIRECTIVE = re.compile(r"^::: ([\w.]+)[ \t]*\n((?:[ \t]+\S.*\n?)*)", re.M)
MEMBERS = re.compile(r"members:\s*\[([^\]]*)\]")


def documented_paths(root: griffe.Object) -> set[str]:
    """Every object path the API pages render, so has an anchor: each ``::: path``
    directive's object and, recursively, its public members that have a docstring (the only
    ones mkdocstrings shows) and are defined there (imports are not rendered), restricted to a
    directive's ``members: [...]`` option where it has one."""
    out: set[str] = set()

    def walk(obj: griffe.Object, only: set[str] | None = None) -> None:
        out.add(obj.path)
        for name, member in obj.members.items():
            if name.startswith("_") or member.is_alias or (only is not None and name not in only):
                continue
            if member.has_docstring:
                walk(member)

    for page in sorted(API_PAGES.glob("*.md")) if API_PAGES.is_dir() else []:
        for path, options in DIRECTIVE.findall(page.read_text(encoding="utf-8")):
            m = MEMBERS.search(options)
            only = {x.strip() for x in m.group(1).split(",")} if m else None
            try:
                target = root.modules_collection[path]
                if target.is_alias:
                    target = target.final_target
            except (KeyError, ValueError, griffe.AliasResolutionError, griffe.CyclicAliasError):
                continue
            walk(target, only)
            out.add(path)  # a re-exported path renders under the name the page gives
    return out


def resolve(name: str, obj: griffe.Object, documented: set[str]) -> str | None:
    """The documented object path ``name`` refers to from inside ``obj``, or None."""
    scopes = []
    node: Any = obj
    while node is not None:
        scopes.append(node.path)
        node = node.parent
    for scope in [*scopes, "dcee", ""]:
        path = f"{scope}.{name}" if scope else name
        try:
            target = obj.modules_collection[path]
            if target.is_alias:
                target = target.final_target
        except (KeyError, ValueError, griffe.AliasResolutionError, griffe.CyclicAliasError):
            continue
        return target.path if target.path in documented else None
    return None


def markdown(doc: str, obj: griffe.Object | None = None, documented: set[str] = frozenset()) -> str:
    """The docstring with roles, literals and literal blocks in Markdown (roles as links where
    ``obj`` and ``documented`` let them resolve)."""

    def role(m: re.Match[str]) -> str:
        name = m.group(2).strip()
        label = name.split(".")[-1] if m.group(1) else name
        target = resolve(name, obj, documented) if obj is not None else None
        return f"[`{label}`][{target}]" if target else f"`{label}`"

    doc = ROLE.sub(role, doc)
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
    """Rewrite every docstring of the loaded package (see the module docstring), once the
    whole package is loaded so that every cross-reference can be resolved."""

    def on_package(self, *, pkg: griffe.Module, **kwargs: Any) -> None:
        documented = documented_paths(pkg)

        def walk(obj: griffe.Object) -> None:
            if obj.docstring is not None:
                obj.docstring.value = markdown(obj.docstring.value, obj, documented)
            for member in obj.members.values():
                if not member.is_alias:
                    walk(member)

        walk(pkg)
