#!/usr/bin/env bash
# The Python package (python/): builds it into a virtual environment of its own, then runs its
# tests with pytest, the examples and the README's Python example among them. CI runs it after
# the workspace's tests; it also works alone (WEFT_PY_VENV picks the environment's folder).
#
# The extension is built by `maturin develop` with cargo's dev profile, in the same target
# folder as the workspace's tests (CARGO_TARGET_DIR is honoured), so the crates already built
# there are reused; `pip install ./python` builds the release profile for users.
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_INCREMENTAL="${CARGO_INCREMENTAL:-0}"
venv="${WEFT_PY_VENV:-$PWD/target/py-venv}"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
  'maturin>=1.9.4,<2' pytest numpy scipy matplotlib mcap mcap-protobuf-support
VIRTUAL_ENV="$venv" PATH="$venv/bin:$PATH" "$venv/bin/maturin" develop --quiet -m python/Cargo.toml
# The CLI the tests compare with (already built by CI's `cargo run`; a no-op then).
cargo build --quiet --bin weft
exec "$venv/bin/python" -m pytest python/tests -q "$@"
