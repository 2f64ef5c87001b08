#!/usr/bin/env python3
"""Checks scripts/check_maps.py on small made-up workspaces: a source file ARCHITECTURE.md does
not name, a name of a file that does not exist, and a module its parent's doc leaves out each
fail it; a workspace whose maps are whole passes."""
import subprocess
import sys
import tempfile
from pathlib import Path

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


def run(files):
    """Exit code and output of the check on a workspace holding `files` (path -> text)."""
    with tempfile.TemporaryDirectory() as d:
        for path, text in files.items():
            f = Path(d) / path
            f.parent.mkdir(parents=True, exist_ok=True)
            f.write_text(text)
        p = subprocess.run([sys.executable, str(SCRIPT), "--root", d], capture_output=True, text=True)
        return p.returncode, p.stdout + p.stderr


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
    passed = failed = 0
    for name, files, want_code, want_text in CASES:
        code, out = run(files)
        if code == want_code and want_text in out:
            passed += 1
        else:
            failed += 1
            print(f"FAIL {name}: exit {code} (want {want_code}), output:\n{out}")
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
