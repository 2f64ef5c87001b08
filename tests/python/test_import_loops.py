#!/usr/bin/env python3
"""Checks scripts/check_import_loops.py on small made-up workspaces: a loop between two
sibling modules (through `use` and through a path written inline) fails it, a tree whose
children only name their parent passes, and test-only modules are left out."""
import sys
from pathlib import Path

from script_cases import check

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "check_import_loops.py"


CASES = [
    (
        "a use loop between siblings",
        {
            "crates/k/src/lib.rs": "mod a;\nmod b;\n",
            "crates/k/src/a.rs": "use crate::b::B;\npub struct A;\n",
            "crates/k/src/b.rs": "use crate::a::{A, other};\npub struct B;\n",
        },
        1,
        "import loop under crate: a, b",
    ),
    (
        "an inline path closes a loop in a folder module",
        {
            "crates/k/src/lib.rs": "mod m;\n",
            "crates/k/src/m/mod.rs": "mod x;\nmod y;\n",
            "crates/k/src/m/x.rs": "use super::y::Y;\npub struct X;\n",
            "crates/k/src/m/y.rs": "pub struct Y;\nfn f() { super::x::go(); }\n",
        },
        1,
        "import loop under crate::m: x, y",
    ),
    (
        "children naming their parent and a one-way chain",
        {
            "src/main.rs": "mod p;\nmod q;\npub struct Root;\n",
            "src/p.rs": "use crate::Root;\nuse crate::q::Q;\n// use crate::p::nothing; a comment\n",
            "src/q.rs": "pub struct Q;\nconst S: &str = \"crate::p::P\";\n",
        },
        0,
        "import loops: none",
    ),
    (
        "a loop through test code only",
        {
            "crates/k/src/lib.rs": "mod a;\nmod b;\n#[cfg(test)]\nmod c;\n",
            "crates/k/src/a.rs": "use crate::b::B;\n#[cfg(test)]\nmod tests {\n    use crate::c::C;\n}\n",
            "crates/k/src/b.rs": "pub struct B;\n",
            "crates/k/src/c.rs": "use crate::a::A;\npub struct C;\n",
        },
        0,
        "import loops: none",
    ),
]


def main():
    return check(SCRIPT, CASES)


if __name__ == "__main__":
    sys.exit(main())
