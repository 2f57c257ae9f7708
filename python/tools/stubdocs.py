"""Writes the compiled module's runtime docstrings into its type stubs.

The docstrings of ``primo._primo`` live in one place, the Rust doc
comments that PyO3 turns into ``__doc__``; ``python/primo/_primo.pyi``
carries copies so that editors show them. This script replaces every
docstring of the stubs (classes, methods, properties, functions) with the
runtime one, so the two cannot drift apart:

    python python/tools/stubdocs.py           # rewrite the stubs
    python python/tools/stubdocs.py --check   # exit 1 if they differ

It imports the installed ``primo``. Names only the stubs have (the
``TypedDict`` results, the learners' shared base classes) keep their
docstrings; a stub-only base class takes its methods' docstrings from its
first subclass in the stubs.
"""

import argparse
import ast
import inspect
import pathlib
import sys

STUBS = pathlib.Path(__file__).resolve().parent.parent / "python" / "primo" / "_primo.pyi"


def _docstring_node(node):
    body = node.body
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
        if isinstance(body[0].value.value, str):
            return body[0]
    return None


def _format(doc, indent):
    """``doc`` as a stub's docstring lines at ``indent`` spaces."""
    if "\\" in doc or '"""' in doc:
        raise ValueError(f"a docstring with a backslash or triple quotes: {doc[:60]!r}")
    pad = " " * indent
    lines = doc.split("\n")
    if len(lines) == 1:
        return [f'{pad}"""{doc}"""']
    out = [f'{pad}"""{lines[0]}']
    out += [f"{pad}{line}" if line else "" for line in lines[1:]]
    out.append(f'{pad}"""')
    return out


def _runtime(module, stub_classes, cls, name):
    """The runtime docstring of ``cls.name`` (or of ``name`` if ``cls`` is
    None); None where the stub's name has no runtime object."""
    if cls is None:
        obj = getattr(module, name, None)
    elif hasattr(module, cls):
        owner = getattr(module, cls)
        obj = owner if name is None else owner.__dict__.get(name)
        if obj is None and name is not None:
            obj = getattr(owner, name, None)
    elif name is None:
        return None  # a stub-only class keeps its own docstring
    else:
        # A stub-only base class: its first subclass in the stubs.
        obj = None
        for sub, bases in stub_classes.items():
            if cls in bases and sub != cls:
                obj = _runtime(module, stub_classes, sub, name)
                if obj is not None:
                    return obj
        return None
    if obj is None:
        return None
    if isinstance(obj, (staticmethod, classmethod)):
        obj = obj.__func__
    doc = getattr(obj, "__doc__", None)
    return inspect.cleandoc(doc) if doc else ""


def _edits(tree, module):
    """(first line, end line, replacement lines) for every docstring."""
    stub_classes = {
        n.name: [b.id for b in n.bases if isinstance(b, ast.Name)]
        for n in tree.body
        if isinstance(n, ast.ClassDef)
    }

    def edit(node, doc):
        if doc is None:
            return None
        indent = node.col_offset + 4
        current = _docstring_node(node)
        if current is not None:
            if not doc:
                raise ValueError(f"line {node.lineno}: {node.name} has no runtime docstring")
            return (current.lineno - 1, current.end_lineno, _format(doc, indent))
        if not doc:
            return None
        first = node.body[0]
        if len(node.body) != 1 or not isinstance(first, ast.Expr):
            raise ValueError(f"line {node.lineno}: {node.name} has a body; give it a docstring")
        return (first.lineno - 1, first.end_lineno, None, indent, doc)

    edits = []
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            edits.append(edit(node, _runtime(module, stub_classes, node.name, None)))
            seen = set()
            for item in node.body:
                if not isinstance(item, ast.FunctionDef) or item.name.startswith("__"):
                    continue
                decorators = [ast.unparse(d) for d in item.decorator_list]
                if any(d.endswith(".setter") for d in decorators) or item.name in seen:
                    continue  # one docstring per name: the property's, the first overload's
                seen.add(item.name)
                edits.append(edit(item, _runtime(module, stub_classes, node.name, item.name)))
        elif isinstance(node, ast.FunctionDef):
            edits.append(edit(node, _runtime(module, stub_classes, None, node.name)))
    return [e for e in edits if e is not None]


def rewritten(text, module):
    """The stubs' text with the runtime docstrings."""
    lines = text.split("\n")
    for e in sorted(_edits(ast.parse(text), module), key=lambda e: e[0], reverse=True):
        if e[2] is not None:
            start, end, new = e
            lines[start:end] = new
        else:
            # `...` after the colon: drop it, put the docstring below.
            start, end, _, indent, doc = e
            head = lines[start]
            if not head.rstrip().endswith("..."):
                raise ValueError(f"line {start + 1}: expected `...` to replace")
            kept = [head.rstrip()[:-3].rstrip()] if head.strip() != "..." else []
            lines[start : start + 1] = kept + _format(doc, indent)
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if the stubs differ")
    args = parser.parse_args()
    import primo._primo as module

    text = STUBS.read_text()
    new = rewritten(text, module)
    if args.check:
        if new != text:
            print(f"{STUBS}: docstrings differ from primo._primo's; run {sys.argv[0]}", file=sys.stderr)
            return 1
        return 0
    if new != text:
        STUBS.write_text(new)
    return 0


if __name__ == "__main__":
    sys.exit(main())
