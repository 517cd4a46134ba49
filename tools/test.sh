#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test suite through ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
SPECIMEN_WERROR=${SPECIMEN_WERROR:-ON} tools/setup.sh
# OpenMP threads that spin while waiting can make two threads slower than one on a shared machine (solver/README.md).
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
ctest --test-dir build --output-on-failure -j"$(nproc)"
