#!/usr/bin/env bash
# Installs what is missing (Debian 12, as root), builds, and runs the main job on the
# embedded default: a 50 x 50 mm 2D specimen for a virtual UCS test (the size of Labra's
# verification specimen, EN 1926), about 5,000 discs with r_max/r_min <= 10. Prints the
# generator's report and the packing metrics; files and pictures go to out/quickstart/.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
build/tools/generate-packing \
  --domain "rectangle 0 0 0.05 0.05" --count 5000 --radius-ratio 10 --seed 1 \
  --output out/quickstart --name ucs_specimen
