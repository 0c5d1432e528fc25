"""MkDocs hooks: the reference pages generated from the code, so that they cannot drift from it.

A page holding ``<!-- generated: study-fields -->`` gets every field of a study file, section by section, from
the study schema (the JSON Schema that ``crx schema`` prints); ``<!-- generated: cli -->`` gets every ``crx``
command with its options, from the parser that ``crx`` itself builds.
"""

from __future__ import annotations

import argparse
import json
import re
from typing import Any

STUDY_MARKER = "<!-- generated: study-fields -->"
CLI_MARKER = "<!-- generated: cli -->"


def on_page_markdown(markdown: str, **_: Any) -> str:
    """Replace each marker by its generated reference."""
    if STUDY_MARKER in markdown:
        markdown = markdown.replace(STUDY_MARKER, study_fields())
    if CLI_MARKER in markdown:
        markdown = markdown.replace(CLI_MARKER, cli_reference())
    return markdown


# --- study files ----------------------------------------------------------------------------------------------


def study_fields() -> str:
    """Every section of a study file as a table: field, what it accepts, default, meaning."""
    from collision_reflex.study.jsonschema import study_json_schema

    schema = study_json_schema()
    definitions = schema.get("$defs", {})
    roots = [_ref_name(option["$ref"]) for option in schema["anyOf"]]
    order = _reachable(roots, definitions)
    out = []
    for name in order:
        definition = definitions[name]
        if "properties" not in definition:
            continue
        out.append(f"### {name} {{#{_anchor(name)}}}\n")
        if definition.get("description"):
            out.append(_one_paragraph(definition["description"]) + "\n")
        out.append("| field | accepts | default | meaning |\n| --- | --- | --- | --- |")
        required = set(definition.get("required", ()))
        for field, spec in definition["properties"].items():
            default = "required" if field in required else _default(spec)
            meaning = _cell(spec.get("description", "") if "$ref" not in spec else "")
            out.append(f"| `{field}` | {_accepts(spec, definitions)} | {default} | {meaning} |")
        out.append("")
    return "\n".join(out)


def _ref_name(ref: str) -> str:
    return ref.rsplit("/", 1)[-1]


def _anchor(name: str) -> str:
    return "schema-" + re.sub(r"[^a-z0-9]+", "-", name.lower()).strip("-")


def _reachable(roots: list[str], definitions: dict[str, Any]) -> list[str]:
    """The definitions reachable from ``roots``, each once, in the order a reader meets them."""
    seen: list[str] = []

    def visit(node: Any) -> None:
        if isinstance(node, dict):
            if "$ref" in node:
                name = _ref_name(node["$ref"])
                if name not in seen:
                    seen.append(name)
                    visit(definitions.get(name, {}))
            for key, value in node.items():
                if key != "$ref":
                    visit(value)
        elif isinstance(node, list):
            for value in node:
                visit(value)

    for root in roots:
        visit({"$ref": f"#/$defs/{root}"})
    return seen


def _accepts(spec: dict[str, Any], definitions: dict[str, Any]) -> str:
    """What a field accepts, in a few words, with links to the sections of nested models."""
    if "$ref" in spec:
        name = _ref_name(spec["$ref"])
        if "properties" in definitions.get(name, {}):
            return f"[{name}](#{_anchor(name)})"
        return _accepts(definitions.get(name, {}), definitions)
    if "const" in spec:
        return f"`{json.dumps(spec['const'])}`"
    if "enum" in spec:
        return " \\| ".join(f"`{json.dumps(v)}`" for v in spec["enum"])
    if "anyOf" in spec:
        kinds = [spec for spec in spec["anyOf"]]
        if _is_quantity(kinds):
            return _quantity(spec)
        parts = [_accepts(kind, definitions) for kind in kinds]
        return " or ".join(dict.fromkeys(part for part in parts if part))
    kind = spec.get("type")
    if kind == "array":
        items = spec.get("items", {})
        count = ""
        if "minItems" in spec or "maxItems" in spec:
            low, high = spec.get("minItems"), spec.get("maxItems")
            count = f" ({low}" + (f" to {high}" if high != low else "") + ")" if low is not None else ""
        return f"list{count} of {_accepts(items, definitions) or 'values'}"
    if kind == "object":
        values = spec.get("additionalProperties")
        return (
            f"mapping of name to {_accepts(values, definitions)}" if isinstance(values, dict) else "mapping"
        )
    if kind == "null":
        return "`null`"
    if kind in ("integer", "number", "string", "boolean"):
        bounds = [
            f"≥ {spec['minimum']:g}" if "minimum" in spec else "",
            f"≤ {spec['maximum']:g}" if "maximum" in spec else "",
        ]
        bounds += [f"> {spec['exclusiveMinimum']:g}" if "exclusiveMinimum" in spec else ""]
        extra = ", ".join(b for b in bounds if b)
        return kind + (f" ({extra})" if extra else "")
    return ""


def _is_quantity(kinds: list[dict[str, Any]]) -> bool:
    """A quantity field: a number (SI) or a string with units."""
    types = {kind.get("type") for kind in kinds}
    return {"number", "string"} <= types and types <= {"number", "string", "null"}


def _quantity(spec: dict[str, Any]) -> str:
    """A quantity: its kind, SI unit and range, from the description its type carries."""
    description = spec.get("description", "")
    match = re.match(r"(?P<what>[^\[]+) \[(?P<unit>[^\]]*)\]", description)
    number = next(kind for kind in spec["anyOf"] if kind.get("type") == "number")
    words = f"{match['what']} [{match['unit'] or '-'}]" if match else "a number or a string with units"
    if "minimum" in number and "maximum" in number:
        words += f", {number['minimum']:g} to {number['maximum']:g}"
    nullable = any(kind.get("type") == "null" for kind in spec["anyOf"])
    return words + (" or `null`" if nullable else "")


def _default(spec: dict[str, Any]) -> str:
    if "default" not in spec:
        return ""
    value = spec["default"]
    text = json.dumps(value) if not isinstance(value, str) or not value else value
    return f"`{text}`" if len(text) <= 40 else "see meaning"


def _cell(text: str) -> str:
    return _one_paragraph(text).replace("|", "\\|")


def _one_paragraph(text: str) -> str:
    return " ".join(text.split())


# --- the command line -----------------------------------------------------------------------------------------


def cli_reference() -> str:
    """Every ``crx`` command: its description and a table of its arguments, from ``crx``'s own parser."""
    from collision_reflex.cli import build_parser

    out = []
    for name, parser in _commands(build_parser(), "crx"):
        out.append(f"### `{name}`\n")
        if parser.description:
            out.append(_one_paragraph(parser.description) + "\n")
        out.append(f"```text\n{parser.format_usage().strip()}\n```\n")
        rows = [row for row in (_argument_row(action) for action in parser._actions) if row]
        if rows:
            out.append("| argument | meaning |\n| --- | --- |")
            out.extend(rows)
        if parser.epilog:
            out.append("\n" + _one_paragraph(parser.epilog))
        out.append("")
    return "\n".join(out)


def _commands(parser: argparse.ArgumentParser, name: str) -> list[tuple[str, argparse.ArgumentParser]]:
    """``parser`` and each of its subcommands' parsers, depth first, with their full command names."""
    found = [(name, parser)]
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub, subparser in action.choices.items():
                found.extend(_commands(subparser, f"{name} {sub}"))
    return found


def _argument_row(action: argparse.Action) -> str:
    if (
        isinstance(action, (argparse._HelpAction, argparse._SubParsersAction))
        or action.help == argparse.SUPPRESS
    ):
        return ""
    flags = ", ".join(action.option_strings) or (action.metavar or action.dest)
    metavar = action.metavar if action.option_strings and action.nargs != 0 else None
    argument = f"`{flags}`" + (f" `{metavar}`" if isinstance(metavar, str) else "")
    help_text = argparse.HelpFormatter("crx")._expand_help(action) if action.help else ""
    return f"| {argument} | {_cell(help_text)} |"
