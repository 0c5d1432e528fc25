"""Limits on a composed YAML node tree, checked before anything is constructed from it.

Study files and part catalogues may come from anyone. A YAML alias repeats a node without repeating its text,
so nine levels of nine aliases ("billion laughs") describe 387 million nodes in a few hundred bytes: every
walk over the constructed data (validation, messages) would take minutes and gigabytes. Tags name Python
objects (``!!python/name:os.system``). :func:`check_nodes` refuses such trees at the offending node, and
:func:`one_line` keeps a message that quotes the file on one printable line.
"""

from __future__ import annotations

import yaml

ALIAS_BUDGET = 10_000
"""How many nodes aliases may add to a document in all: a study repeats a block a few times, never thousands."""

MAX_SCALAR_LENGTH = 10_000
"""Longest scalar [characters]: a long description fits; a value that long is a mistake or an attack."""

MAX_DEPTH = 200
"""Deepest nesting of mappings and lists: a study nests a few levels. libyaml's composer recurses in C, so a
file nested some ten thousand levels deep crashed the interpreter (a segmentation fault, no RecursionError)."""

LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
"""The safe loader, on libyaml's parser where PyYAML was built with it (faster; the same marks)."""

# What the safe loader constructs, and merge keys (``<<: *defaults``), which it flattens.
_PLAIN_TAGS = (frozenset(yaml.SafeLoader.yaml_constructors) - {None}) | {"tag:yaml.org,2002:merge"}


NodePath = tuple[str | int, ...]
"""Where a node is: the mapping keys (as written) and list indices from the root."""


class NodeProblem(ValueError):
    """A node tree over a limit: ``reason`` (a short phrase), the node's ``path`` and 1-based ``line``, ``column``."""

    def __init__(self, reason: str, node: yaml.Node | yaml.Event, path: NodePath = ()) -> None:
        super().__init__(reason)
        self.reason = reason
        self.path = path
        self.line = node.start_mark.line + 1
        self.column = node.start_mark.column + 1


def check_depth(text: str, max_nodes: int | None = None) -> None:
    """Refuse ``text`` nested deeper than :data:`MAX_DEPTH`, from its parse events, before it is composed.

    Also refuse more than ``max_nodes`` nodes (scalars, mappings and lists written), if given: composing and
    checking a node costs about 10 us, so a catalogue of 400,000 short lines took 6 s to refuse.
    Raises :class:`NodeProblem` at the first node too deep or too many; a YAML error as composing would.
    """
    depth = nodes = 0
    for event in yaml.parse(text, Loader=LOADER):
        if isinstance(event, yaml.NodeEvent) and not isinstance(event, yaml.AliasEvent):
            nodes += 1
            if max_nodes is not None and nodes > max_nodes:
                raise NodeProblem(f"more than {max_nodes} values", event)
        if isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
            depth += 1
            if depth > MAX_DEPTH:
                raise NodeProblem(f"nested deeper than {MAX_DEPTH} levels", event)
        elif isinstance(event, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
            depth -= 1


def check_nodes(root: yaml.Node) -> None:
    """Refuse a node tree that aliases expand beyond :data:`ALIAS_BUDGET`, or with a bad node.

    A bad node is a scalar longer than :data:`MAX_SCALAR_LENGTH`, a string that is not valid text (a lone
    surrogate or a NUL character, which no file name or frame name holds), or a tag the safe loader does not
    construct. Aliases that refer to their own ancestor (a recursive structure) are refused too.

    Raises
    ------
    NodeProblem
        At the first offending node.
    """
    sizes: dict[int, int] = {}
    try:
        expanded = _expanded_size(root, sizes, set(), ())
    except RecursionError:
        raise NodeProblem("nesting too deep", root) from None
    if expanded - len(sizes) > ALIAS_BUDGET:
        raise NodeProblem(
            f"aliases that expand to {_count(expanded)} nodes from {len(sizes)} written (at most "
            f"{ALIAS_BUDGET} repeated nodes)",
            _largest_repeated(root, sizes),
        )


def _expanded_size(node: yaml.Node, sizes: dict[int, int], open_nodes: set[int], path: NodePath) -> int:
    """Number of nodes below and including ``node`` with every alias expanded (memoised in ``sizes``)."""
    key = id(node)
    if key in sizes:
        return sizes[key]
    if key in open_nodes:
        raise NodeProblem("a recursive alias (a node that contains itself)", node, path)
    _check_node(node, path)
    open_nodes.add(key)
    size = 1
    if isinstance(node, yaml.SequenceNode):
        for index, item in enumerate(node.value):
            size += _expanded_size(item, sizes, open_nodes, (*path, index))
    elif isinstance(node, yaml.MappingNode):
        for key_node, value_node in node.value:
            name = key_node.value if isinstance(key_node, yaml.ScalarNode) else "?"
            size += _expanded_size(key_node, sizes, open_nodes, (*path, name))
            size += _expanded_size(value_node, sizes, open_nodes, (*path, name))
    open_nodes.discard(key)
    sizes[key] = size
    return size


def _check_node(node: yaml.Node, path: NodePath) -> None:
    if node.tag not in _PLAIN_TAGS:
        raise NodeProblem(f"the tag {_shown(node.tag)} (only plain YAML values are read)", node, path)
    if isinstance(node, yaml.ScalarNode):
        text = node.value
        if len(text) > MAX_SCALAR_LENGTH:
            raise NodeProblem(f"a value of {len(text)} characters (at most {MAX_SCALAR_LENGTH})", node, path)
        if "\x00" in text:
            raise NodeProblem("a NUL character in a value", node, path)
        try:
            text.encode("utf-8")
        except UnicodeEncodeError:
            raise NodeProblem("a lone surrogate (not a Unicode character) in a value", node, path) from None


def _largest_repeated(root: yaml.Node, sizes: dict[int, int]) -> yaml.Node:
    """The deepest node whose expansion alone is over the budget: where the repetition is written."""
    node = root
    while True:
        children = (
            node.value
            if isinstance(node, yaml.SequenceNode)
            else [value for _, value in node.value]
            if isinstance(node, yaml.MappingNode)
            else []
        )
        over = [child for child in children if sizes.get(id(child), 0) > ALIAS_BUDGET]
        if not over:
            return node
        node = over[0]


def _shown(tag: str) -> str:
    short = tag.replace("tag:yaml.org,2002:", "!!")
    return repr(short if len(short) <= 40 else short[:37] + "...")


def _count(number: int) -> str:
    return f"{number:.2g}" if number >= 1e6 else str(number)


def one_line(text: str) -> str:
    r"""``text`` with line breaks, control characters and lone surrogates escaped (``\n``, ``\ud800``).

    For messages that quote a file: each stays one line of printable text, whatever the file holds.
    """
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in text)
