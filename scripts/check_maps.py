#!/usr/bin/env python3
"""Fail when the maps of the code fall behind it.

Two maps are checked against the tree:
- ARCHITECTURE.md names every Rust source file of the crates (crates/*/src, the app's src/,
  python/src), written as its path within its crate's `src/` (`trimesh/bvh.rs`) or whole, and
  names no `.rs` file that does not exist;
- the doc comment (`//!`) of every `lib.rs`, `main.rs` and `mod.rs` names each module it
  declares (`mod x;`, `pub mod x;`), tests modules called `tests` apart.

Usage: python3 scripts/check_maps.py [--root DIR]
(--root: the workspace to read, by default the one this script lies in.)
Exit 0 when both maps hold, 1 otherwise (each gap printed), 2 on a usage error.
"""
import re
import sys
from pathlib import Path

MOD_DECL = re.compile(r"^\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+([a-z_][a-z0-9_]*)\s*;", re.M)
NAMED_RS = re.compile(r"`([A-Za-z0-9_./-]+\.rs)`")


def sources(root):
    """Each source file of the crates, as (path from the root, path within its `src/`)."""
    dirs = sorted(root.glob("crates/*/src")) + [root / "src", root / "python" / "src"]
    out = []
    for d in dirs:
        if d.is_dir():
            for f in sorted(d.rglob("*.rs")):
                out.append((f.relative_to(root).as_posix(), f.relative_to(d).as_posix()))
    return out


def architecture_gaps(root, files):
    """Files ARCHITECTURE.md leaves out, and `.rs` names in it that match no file."""
    arch = root / "ARCHITECTURE.md"
    if not arch.is_file():
        return ["ARCHITECTURE.md: missing"]
    text = arch.read_text()
    named = set(NAMED_RS.findall(text))
    gaps = []
    for whole, inner in files:
        # python/'s own table names its files from the package folder (`src/lib.rs`).
        package = whole.split("/", 1)[1] if whole.startswith("python/") else whole
        if not any(f"`{n}`" in text for n in (inner, whole, package)):
            gaps.append(f"ARCHITECTURE.md does not name {whole}")
    every = [f.relative_to(root).as_posix() for f in root.rglob("*.rs")
             if "target" not in f.relative_to(root).parts[:1]]
    known = set(every) | {inner for _, inner in files}
    for name in sorted(named):
        if name not in known and not any(w.endswith("/" + name) for w in every):
            gaps.append(f"ARCHITECTURE.md names {name}, which does not exist")
    return gaps


def module_doc_gaps(root, files):
    """Modules a `lib.rs`, `main.rs` or `mod.rs` declares but its `//!` doc does not name."""
    gaps = []
    for whole, _ in files:
        if Path(whole).name not in ("lib.rs", "main.rs", "mod.rs"):
            continue
        text = (root / whole).read_text()
        doc = "\n".join(line for line in text.splitlines() if line.lstrip().startswith("//!"))
        for m in MOD_DECL.findall(text):
            if m != "tests" and not re.search(rf"`{m}`|\b{m}\.rs\b|`{m}/", doc):
                gaps.append(f"{whole}: its doc does not name module `{m}`")
    return gaps


def main(argv):
    root = Path(__file__).resolve().parent.parent
    if argv[:1] == ["--root"] and len(argv) == 2:
        root = Path(argv[1])
    elif argv:
        print(__doc__.strip().splitlines()[-3], file=sys.stderr)
        return 2
    files = sources(root)
    gaps = architecture_gaps(root, files) + module_doc_gaps(root, files)
    for g in gaps:
        print(g)
    if gaps:
        return 1
    print(f"maps: {len(files)} source files named, every module listed in its parent's doc")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
