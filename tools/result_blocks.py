"""Marked blocks of the results pages (docs/results/*.md): the text between ``<!-- NAME:begin -->`` and ``<!-- NAME:end -->`` lines, which
``tools/regenerate_results.py`` rewrites from the output of the script that measures them."""

from __future__ import annotations

import re

MARKER = re.compile(r"^<!-- ([a-z0-9-]+):(begin|end) -->$", re.M)


def block_names(text: str) -> list[str]:
    """Names of the marked blocks in text, in order; ValueError if a marker is unpaired, nested or repeated."""
    names, open_name = [], None
    for match in MARKER.finditer(text):
        name, kind = match.groups()
        if kind == "begin":
            if open_name is not None or name in names:
                raise ValueError(f"marker <!-- {name}:begin --> inside block {open_name!r} or repeated")
            open_name = name
        else:
            if name != open_name:
                raise ValueError(f"marker <!-- {name}:end --> closes {open_name!r}")
            names.append(name)
            open_name = None
    if open_name is not None:
        raise ValueError(f"block {open_name!r} has no <!-- {open_name}:end --> marker")
    return names


def block_spans(text: str) -> dict[str, tuple[int, int]]:
    """{name: (first, last) line number (1-based) of the block's content}."""
    spans, begin = {}, {}
    for number, line in enumerate(text.splitlines(), start=1):
        match = MARKER.match(line)
        if match and match.group(2) == "begin":
            begin[match.group(1)] = number + 1
        elif match:
            spans[match.group(1)] = (begin[match.group(1)], number - 1)
    return spans


def replace_block(text: str, name: str, block: str) -> str:
    """text with the content of block ``name`` replaced by ``block``; ValueError if the text lacks it."""
    if name not in block_names(text):
        raise ValueError(f"no block <!-- {name}:begin --> … <!-- {name}:end -->")
    begin, end = f"<!-- {name}:begin -->", f"<!-- {name}:end -->"
    head, rest = text.split(begin)
    _, tail = rest.split(end)
    return f"{head}{begin}\n{block.strip()}\n{end}{tail}"
