#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test suite through ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
SPECIMEN_WERROR=${SPECIMEN_WERROR:-ON} tools/setup.sh
ctest --test-dir build --output-on-failure -j"$(nproc)"
