#!/usr/bin/env bash
# The test command of README.md (and CI): installs what the tests need when it is missing,
# then runs every test of the workspace with one wgpu backend for the whole run.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-test-deps.sh
# One backend for every test that draws: Vulkan through Mesa's lavapipe (software), unless
# the caller chose another (WGPU_BACKEND=gl uses OpenGL/EGL on llvmpipe).
export WGPU_BACKEND="${WGPU_BACKEND:-vulkan}"
# A from-scratch test build without incremental state is gigabytes smaller on disk (CI
# builds once and never again); a developer may set CARGO_INCREMENTAL=1 to keep it.
export CARGO_INCREMENTAL="${CARGO_INCREMENTAL:-0}"
exec cargo test --workspace "$@"
