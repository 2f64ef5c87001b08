#!/usr/bin/env python3
"""Checks scripts/check_maps.py on small made-up workspaces: a source file ARCHITECTURE.md does
not name, a name of a file that does not exist, and a module its parent's doc leaves out each
fail it; a workspace whose maps are whole passes."""
import sys
from pathlib import Path

from script_cases import check

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "check_maps.py"

LIB = "//! The crate. Its modules: `a` (an a) and `m` (the m folder).\nmod a;\nmod m;\n"
MOD = "//! The m folder: `x` holds an x.\nmod x;\n#[cfg(test)]\nmod tests;\n"
WHOLE = {
    "crates/k/src/lib.rs": LIB,
    "crates/k/src/a.rs": "//! An a.\n",
    "crates/k/src/m/mod.rs": MOD,
    "crates/k/src/m/x.rs": "//! An x.\n",
    "crates/k/src/m/tests.rs": "//! Tests.\n",
    "crates/k/benches/b.rs": "fn main() {}\n",
    "ARCHITECTURE.md": "| `lib.rs` | | `a.rs` | | `m/mod.rs` | | `m/x.rs` | | `m/tests.rs` |\n"
    "Benches: `crates/k/benches/b.rs`.\n",
}


CASES = [
    ("whole maps", WHOLE, 0, "maps: 5 source files named"),
    (
        "a file the map leaves out",
        {
            **WHOLE,
            "crates/k/src/m/y.rs": "//! A y.\n",
            "crates/k/src/m/mod.rs": MOD.replace("`x` holds an x.", "`x` and `y`.") + "mod y;\n",
        },
        1,
        "ARCHITECTURE.md does not name crates/k/src/m/y.rs",
    ),
    (
        "a name of a file that is gone",
        {**WHOLE, "ARCHITECTURE.md": WHOLE["ARCHITECTURE.md"] + "| `m/gone.rs` |\n"},
        1,
        "ARCHITECTURE.md names m/gone.rs, which does not exist",
    ),
    (
        "a module its parent's doc leaves out",
        {**WHOLE, "crates/k/src/lib.rs": "//! The crate: `a`.\nmod a;\nmod m;\n"},
        1,
        "crates/k/src/lib.rs: its doc does not name module `m`",
    ),
]


def main():
    return check(SCRIPT, CASES)


if __name__ == "__main__":
    sys.exit(main())
