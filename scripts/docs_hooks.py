"""MkDocs hooks: reference pages generated from the code at build time, so they cannot drift.

* ``reference/cli.md``: the ``--help`` of every ``dcee`` command (from the click objects).
* ``reference/scenario.md``: every scenario field with its type, default, allowed range and
  description (from the pydantic models; the descriptions are the attribute docstrings).
* Every page, written or generated, is refused if its Markdown or its HTML holds a control
  character (a ``\\b`` typed into a Python string as ``\b`` becomes a backspace and breaks the
  equation around it, which only a browser would show).
"""

from __future__ import annotations

import re
import types
import typing
from typing import Any

import click
from mkdocs.exceptions import PluginError
from mkdocs.structure.files import File, Files

CONTROL_CHARACTER = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]")
"""Any C0 control character but tab, newline and carriage return, and DEL."""


def control_characters(text: str) -> list[str]:
    """Where ``text`` holds a control character: ``"line L: U+00XX"`` for each (empty: none)."""
    return [
        f"line {text.count(chr(10), 0, m.start()) + 1}: U+{ord(m.group()):04X}"
        for m in CONTROL_CHARACTER.finditer(text)
    ]


def _refuse_control_characters(text: str, where: str) -> None:
    found = control_characters(text)
    if found:
        raise PluginError(f"{where}: control character at {', '.join(found[:3])}")


def on_page_markdown(markdown: str, page: Any, config: Any, files: Files) -> str:
    _refuse_control_characters(markdown, page.file.src_uri)
    return markdown


def on_post_page(output: str, page: Any, config: Any) -> str:
    _refuse_control_characters(output, f"{page.file.dest_uri} (built)")
    return output


def on_files(files: Files, config: Any) -> Files:
    files.append(File.generated(config, "reference/cli.md", content=cli_reference()))
    files.append(File.generated(config, "reference/scenario.md", content=scenario_reference()))
    return files


def cli_reference() -> str:
    from dcee.cli import cli

    out = [
        "# Command reference",
        "",
        "Generated from the command line's own definitions when the documentation is built. "
        "How to use them: [the command line](../guide/command-line.md).",
        "",
    ]
    root = click.Context(cli, info_name="dcee")
    out += ["## `dcee`", "", "```text", cli.get_help(root), "```", ""]
    for name in sorted(cli.commands):
        cmd = cli.commands[name]
        ctx = click.Context(cmd, info_name=f"dcee {name}", parent=root)
        out += [f"## `dcee {name}`", "", "```text", cmd.get_help(ctx), "```", ""]
    return "\n".join(out)


def scenario_reference() -> str:
    from pydantic import BaseModel

    from dcee.scenarios import schema as config

    # one section per truth kind with a parameter table, from the one registry of truth kinds
    truth_kinds = [
        (
            f'[truth] model: kind = "{kind}"' + (" (or file = …)" if kind == "playback" else ""),
            k.spec,
        )
        for kind, k in config.TRUTH_KINDS.items()
        if k.spec is not None
    ]
    sections = [
        ("top level", config.Scenario),
        ("[volume]", config.Volume),
        ("[truth]", config.Truth),
        *truth_kinds,
        ("[prior] NAME: one parameter's prior", config.PriorSpec),
        ("[sensor]", config.SensorSpec),
        ("[estimator]", config.EstimatorSpec),
        ("[agent]", config.AgentSpec),
        ("[agent.unicycle]", config.UnicycleSpec),
        ("[search]", config.SearchSpec),
    ]
    out = [
        "# Scenario reference",
        "",
        "Generated from the validating models (`dcee.scenarios`) when the documentation "
        "is built. A scenario is a TOML file; `dcee show paper:1` prints a complete one, and "
        "`dcee schema` the JSON Schema of the same models (for editors). Why each default is "
        "what it is: [scenarios](../scenarios.md).",
        "",
    ]
    for title, model in sections:
        out += [f"## {title}", ""]
        doc = (model.__doc__ or "").strip()
        if doc and not doc.startswith("!!!"):
            out += [" ".join(doc.split()), ""]
        out += ["| field | type | default | allowed | description |", "|---|---|---|---|---|"]
        for name, field in model.model_fields.items():
            default = "required" if field.is_required() else _fmt_default(field)
            if isinstance(field.default, BaseModel):
                default = "see its section"
            out.append(
                f"| `{name}` | {_fmt_type(field.annotation)} | {default} "
                f"| {_fmt_constraints(field.metadata)} | {_cell(field.description or '')} |"
            )
        out.append("")
    return "\n".join(out)


def _fmt_default(field: Any) -> str:
    if field.default_factory is not None:
        return "(computed)"
    value = field.default
    return "unset" if value is None else f"`{value!r}`"


def _fmt_type(annotation: Any) -> str:
    origin = typing.get_origin(annotation)
    if origin is typing.Literal:
        return " \\| ".join(f"`{a!r}`" for a in typing.get_args(annotation))
    if origin in (typing.Union, types.UnionType):
        return " or ".join(_fmt_type(a) for a in typing.get_args(annotation))
    if origin is typing.Annotated:
        return _fmt_type(typing.get_args(annotation)[0])
    if origin in (list, tuple, dict):
        args = ", ".join(_fmt_type(a) for a in typing.get_args(annotation) if a is not Ellipsis)
        return f"{origin.__name__}[{args}]"
    if annotation is type(None):
        return "none"
    return getattr(annotation, "__name__", str(annotation)).replace("|", "\\|")


def _fmt_constraints(metadata: list[Any]) -> str:
    parts = []
    for m in metadata:
        for attr, sym in (("gt", ">"), ("ge", "≥"), ("lt", "<"), ("le", "≤")):
            if getattr(m, attr, None) is not None:
                parts.append(f"{sym} {getattr(m, attr)}")
        if getattr(m, "allow_inf_nan", None) is False:
            parts.append("finite")
    return ", ".join(parts)


def _cell(text: str) -> str:
    return " ".join(text.split()).replace("|", "\\|")
