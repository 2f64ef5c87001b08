#!/usr/bin/env python3
"""Fail when modules of a crate import each other in a loop.

For every crate of the workspace (crates/*/src and the app's src/), each module's children
are the nodes of one graph: child A has an arrow to sibling B when code under A names a path
into B (`use crate::…`, `super::…`, `self::…`, or a path written inline in the code).
A cycle among siblings at any level of the module tree is an import loop: B can then not be
read or changed without A, nor A without B. Test code (`#[cfg(test)]` modules, `tests.rs`,
`tests/` folders) is left out, as test-only imports do not shape the library.

A parent naming its own children (`mod a; pub use a::X;`) and a child naming items defined in
its parent's own file are the module tree itself, not loops, and are not counted.

Usage: python3 scripts/check_import_loops.py [--verbose] [--root DIR]
(--root: the workspace to read, by default the one this script lies in.)
Exit 0 when no crate has a loop, 1 otherwise (each loop printed with the names behind each
arrow), 2 on a usage error.
"""
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# `mod name;` with the attributes written just before it (`#[cfg(test)]` marks test code).
MOD_DECL = re.compile(
    r"((?:^\s*#\[[^\]]*\][ \t]*\n)*)^\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+([a-z_][a-z0-9_]*)\s*;", re.M
)
# A path that starts at the crate root or at a parent: crate::a::b, super::super::a, self::a.
PATH = re.compile(r"\b(crate|super|self)((?:\s*::\s*[A-Za-z_][A-Za-z0-9_]*)+)")
# `use` groups: crate::{a::X, b::{Y, Z}} — expanded before paths are read.
USE_STMT = re.compile(r"\buse\s+([^;]+);", re.S)


def strip_comments(text):
    """The code without comments and without the contents of string and char literals."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            depth, i = 1, i + 2
            while i < n and depth:
                if text.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                elif text.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                else:
                    i += 1
        elif (m := re.match(r'b?r(#*)"', text[i : i + 260])) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            end = '"' + m.group(1)
            j = text.find(end, i + m.end())
            out.append('""')
            i = n if j < 0 else j + len(end)
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append('""')
            i = j + 1
        elif c == "'" and (m := re.match(r"'(?:\\.[^']*|[^'\\])'", text[i : i + 12])):
            out.append("' '")
            i += m.end()
        else:
            out.append(c)
            i += 1
    return "".join(out)


def strip_test_modules(text):
    """The code without `#[cfg(test)] mod name { … }` blocks (brace-matched)."""
    out, i = [], 0
    pat = re.compile(r"#\[cfg\(test\)\]\s*(?:pub\s+)?mod\s+\w+\s*\{")
    while True:
        m = pat.search(text, i)
        if not m:
            out.append(text[i:])
            return "".join(out)
        out.append(text[i : m.start()])
        depth, j = 1, m.end()
        while j < len(text) and depth:
            depth += {"{": 1, "}": -1}.get(text[j], 0)
            j += 1
        i = j


def expand_use(body):
    """`crate::{a::X, b::{Y, Z}}` as the flat paths crate::a::X, crate::b::Y, crate::b::Z."""
    body = re.sub(r"\s+", "", body)

    def split_top(s):
        parts, depth, cur = [], 0, ""
        for ch in s:
            if ch == "," and depth == 0:
                parts.append(cur)
                cur = ""
                continue
            depth += {"{": 1, "}": -1}.get(ch, 0)
            cur += ch
        parts.append(cur)
        return [p for p in parts if p]

    def walk(prefix, s):
        if "{" not in s:
            return [prefix + s]
        head, rest = s.split("{", 1)
        inner = rest[: rest.rfind("}")]
        paths = []
        for part in split_top(inner):
            paths += walk(prefix + head, part)
        return paths

    return walk("", body)


class Module:
    """One module: its path from the crate root, its file, and its child modules."""

    def __init__(self, path, file):
        self.path = path  # tuple of names from the crate root
        self.file = file
        self.children = {}


def module_tree(root_file):
    """The crate's module tree, read from `mod name;` lines, test modules left out."""

    def load(path, file):
        mod = Module(path, file)
        text = strip_test_modules(strip_comments(file.read_text()))
        is_dir_owner = file.name in ("mod.rs", "lib.rs", "main.rs")
        base = file.parent if is_dir_owner else file.parent / file.stem
        for m in MOD_DECL.finditer(text):
            attrs, name = m.group(1), m.group(2)
            if "cfg(test)" in attrs.replace(" ", "") or name == "tests":
                continue
            for cand in (base / f"{name}.rs", base / name / "mod.rs"):
                if cand.exists():
                    mod.children[name] = load(path + (name,), cand)
                    break
        return mod

    return load((), root_file)


def all_modules(mod):
    yield mod
    for c in mod.children.values():
        yield from all_modules(c)


def resolve(mod, path_text):
    """The absolute module path (tuple of names, items included) a path written in `mod` names."""
    segs = [s for s in re.split(r"\s*::\s*", path_text) if s]
    if not segs:
        return None
    # A file's own module: items in mod.rs/lib.rs belong to that module itself.
    here = list(mod.path)
    head = segs[0]
    if head == "crate":
        base, rest = [], segs[1:]
    elif head in ("super", "self"):
        base = here[:]
        i = 0
        while i < len(segs) and segs[i] in ("super", "self"):
            if segs[i] == "super":
                if not base:
                    return None
                base.pop()
            i += 1
        rest = segs[i:]
    else:
        return None
    return tuple(base + rest)


def edges_of(root):
    """(from module path, to absolute path, the name used) for every path in the crate."""
    for mod in all_modules(root):
        text = strip_test_modules(strip_comments(mod.file.read_text()))
        paths = []
        for m in USE_STMT.finditer(text):
            paths += [p for p in expand_use(m.group(1)) if re.match(r"(crate|super|self)::", p)]
        text_wo_use = USE_STMT.sub("", text)
        for m in PATH.finditer(text_wo_use):
            paths.append(m.group(1) + m.group(2))
        for p in paths:
            target = resolve(mod, p)
            if target is not None:
                yield mod.path, target, p


def sibling_edges(root):
    """Arrows between siblings: {(parent path): {(a, b): set of names}}."""
    known = {m.path for m in all_modules(root)}
    graph = {}
    for src, dst, name in edges_of(root):
        # Longest prefix of dst that is a module.
        k = len(dst)
        while k > 0 and dst[:k] not in known:
            k -= 1
        dst_mod = dst[:k]
        # The common ancestor and the two siblings under it.
        n = 0
        while n < len(src) and n < len(dst_mod) and src[n] == dst_mod[n]:
            n += 1
        if n == len(src) or n == len(dst_mod):
            continue  # one is an ancestor of the other: the module tree itself
        parent = src[:n]
        a, b = src[n], dst_mod[n]
        graph.setdefault(parent, {}).setdefault((a, b), set()).add(name)
    return graph


def cycles(edges):
    """Strongly connected components of more than one node (Tarjan)."""
    nodes = sorted({a for a, _ in edges} | {b for _, b in edges})
    adj = {n: sorted(b for (a, b) in edges if a == n) for n in nodes}
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def strong(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in adj[v]:
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for n in nodes:
        if n not in index:
            strong(n)
    return out


def crate_roots(root):
    """(crate name, root file) for every crate of the workspace at `root`."""
    roots = []
    for lib in sorted(root.glob("crates/*/src/lib.rs")):
        roots.append((lib.parent.parent.name, lib))
    for main in (root / "src" / "main.rs", root / "src" / "lib.rs"):
        if main.exists():
            roots.append(("weft (" + main.name + ")", main))
    return roots


def main(argv):
    verbose, root, args = False, ROOT, list(argv)
    while args:
        a = args.pop(0)
        if a == "--verbose":
            verbose = True
        elif a == "--root" and args:
            root = Path(args.pop(0))
        else:
            print(__doc__, file=sys.stderr)
            return 2
    found = 0
    for crate, root_file in crate_roots(root):
        tree = module_tree(root_file)
        graph = sibling_edges(tree)
        n_mods = sum(1 for _ in all_modules(tree))
        crate_loops = 0
        for parent, edges in sorted(graph.items()):
            for comp in cycles(edges):
                crate_loops += 1
                where = "::".join(("crate",) + parent)
                print(f"{crate}: import loop under {where}: {', '.join(comp)}")
                for (a, b), names in sorted(edges.items()):
                    if a in comp and b in comp:
                        shown = ", ".join(sorted(names)[:4])
                        more = f" and {len(names) - 4} more" if len(names) > 4 else ""
                        print(f"    {a} -> {b}: {shown}{more}")
        found += crate_loops
        if verbose or crate_loops:
            print(f"{crate}: {n_mods} modules, {crate_loops} loop(s)")
    if found:
        print(f"import loops: {found} found", file=sys.stderr)
        return 1
    print("import loops: none")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
