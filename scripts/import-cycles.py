#!/usr/bin/env python3
"""Usage: scripts/import-cycles.py [CRATE_DIR ...] -- prints the import cycles among the files of each crate (default: every crates/*), exits 1 if there is one."""

# A file's module is its path under src/ (src/a.rs and src/a/b.rs are modules a and a::b; lib.rs
# is the crate's root). A file uses another when it names it by a `crate::` or `super::` path,
# in a `use` (grouped ones included) or in code; a path to a::b counts as a use of a's file
# unless a/b.rs exists, and a path to an item of the root as a use of lib.rs. Comments and
# string literals are not read. A bin target's main.rs beside a lib.rs is its own crate, so its
# `crate::` paths are not counted.

import re
import sys
from pathlib import Path


def strip(text):
    """`text` with comments, strings and char literals blanked (newlines kept)."""
    out = []
    i, n = 0, len(text)
    blank = lambda s: re.sub(r"[^\n]", " ", s)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(blank(text[i:j]))
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(blank(text[i:j]))
            i = j
        elif (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")) and (
            m := re.match(r'b?r(#*)"', text[i : i + 300])
        ):
            end = '"' + m.group(1)
            j = text.find(end, i + m.end())
            j = n if j < 0 else j + len(end)
            out.append(blank(text[i:j]))
            i = j
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append(blank(text[i : j + 1]))
            i = j + 1
        elif c == "'" and (m := re.match(r"'(\\.[^']*|[^\\'])'", text[i : i + 12])):
            out.append(blank(m.group(0)))
            i += m.end()
        else:
            out.append(c)
            i += 1
    return "".join(out)


def use_paths(tree):
    """The full paths a `use` tree names: `a::{b, c::{d as e}}` gives a::b and a::c::d."""
    tree = re.sub(r"\s+", "", re.sub(r"\s+as\s+\w+", "", tree))
    paths = []

    def expand(prefix, t):
        parts, depth, start = [], 0, 0
        for k, ch in enumerate(t):
            depth += ch == "{"
            depth -= ch == "}"
            if ch == "," and depth == 0:
                parts.append(t[start:k])
                start = k + 1
        parts.append(t[start:])
        for part in filter(None, parts):
            brace = part.find("{")
            if brace >= 0:
                head = [s for s in part[:brace].split("::") if s]
                expand(prefix + head, part[brace + 1 : part.rindex("}")])
            else:
                segments = [s for s in part.split("::") if s not in ("", "self", "*")]
                paths.append(prefix + segments)

    expand([], tree)
    return paths


def modules(src):
    """Module path (tuple) -> file, for every .rs file under `src`."""
    found = {}
    for f in sorted(src.rglob("*.rs")):
        rel = f.relative_to(src).with_suffix("").parts
        if rel[0] == "bin":
            continue
        if rel in (("lib",), ("main",)):
            if rel == ("main",) and (src / "lib.rs").exists():
                continue
            rel = ()
        elif rel[-1] == "mod":
            rel = rel[:-1]
        found[rel] = f
    return found


def references(text, module):
    """(line, module path) for every `crate::` or `super::` path in `text`, a file of `module`."""
    text = strip(text)
    # The inline modules (`mod tests { ... }`) open at each offset, for resolving `super::`.
    inline, stack, depth = [], [], 0
    for m in re.finditer(r"\bmod\s+(\w+)\s*\{|[{}]", text):
        if m.group(1):
            stack.append((m.group(1), depth))
            depth += 1
        elif m.group(0) == "{":
            depth += 1
        else:
            depth -= 1
            if stack and stack[-1][1] == depth:
                stack.pop()
        inline.append((m.start(), tuple(name for name, _ in stack)))

    def scope(offset):
        current = ()
        for start, names in inline:
            if start > offset:
                break
            current = names
        return tuple(module) + current

    def resolve(path, offset):
        base = scope(offset)
        while path and path[0] == "super":
            base, path = base[:-1], path[1:]
        if path and path[0] == "crate":
            base, path = (), path[1:]
        return base + tuple(path)

    line = lambda offset: text.count("\n", 0, offset) + 1
    refs = []
    for m in re.finditer(r"\buse\s+((?:crate|super)\b[^;]*);", text):
        for path in use_paths(m.group(1)):
            refs.append((line(m.start()), resolve(path, m.start())))
    for m in re.finditer(r"\b((?:super\s*::\s*)+|crate\s*::\s*)((?:\w+\s*::\s*)*\w+)", text):
        path = re.sub(r"\s+", "", m.group(0)).split("::")
        refs.append((line(m.start()), resolve(path, m.start())))
    return refs


def graph(crate):
    """file -> {file it uses: first line that uses it} for the files of `crate`'s src/."""
    src = crate / "src"
    files = modules(src)
    edges = {f: {} for f in files.values()}
    for module, f in files.items():
        for lineno, path in references(f.read_text(encoding="utf-8"), module):
            target = next((files[path[:k]] for k in range(len(path), -1, -1) if path[:k] in files), None)
            if target is not None and target != f:
                edges[f].setdefault(target, lineno)
    return edges


def cycles(edges):
    """The strongly connected components of more than one file (Tarjan), each sorted."""
    index, low, on_stack, stack, found = {}, {}, set(), [], []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    sys.setrecursionlimit(10_000)
    for v in sorted(edges):
        if v not in index:
            visit(v)
    return found


def main(args):
    root = Path(__file__).resolve().parent.parent
    crates = [Path(a) for a in args] or sorted(p for p in (root / "crates").iterdir() if (p / "src").is_dir())
    any_cycle = False
    for crate in crates:
        edges = graph(crate)
        for component in cycles(edges):
            any_cycle = True
            names = lambda f: str(f.relative_to(crate))
            print(f"{crate.name}: cycle among {', '.join(names(f) for f in component)}")
            for f in component:
                for target, lineno in sorted(edges[f].items()):
                    if target in component:
                        print(f"    {names(f)}:{lineno} uses {names(target)}")
    return 1 if any_cycle else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
