#!/usr/bin/env bash
# Installs what is missing (Debian 12, as root), builds, and runs the main job on the
# embedded default: calibrate a bonded 2D DEM model to the bundled rock of Labra, Onate &
# Rojek (2012), data/materials/labra2012_rock.toml (E 18.691 GPa, nu 0.20, UCS 127.83 MPa,
# sigma_t 12.30 MPa). It generates the 50 x 50 mm UCS specimen (about 5,000 discs) and its
# Brazilian disc, takes the micro-macro maps shipped in data/maps/ (or builds them, about
# 10-15 minutes, when this machine's packing differs), measures the reach, calibrates E and
# nu by elastic runs and the strengths by rounds of UCS and Brazilian tests, and prints the
# report. Files and pictures go to out/quickstart/.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
# OpenMP threads that spin while waiting can make two threads slower than one on a shared machine (solver/README.md).
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
# Work on a copy of the shipped maps: calibrations append their verifications to the map file.
mkdir -p out/quickstart/maps
cp -n data/maps/*.json out/quickstart/maps/ 2>/dev/null || true
build/tools/calibrate-to-material data/materials/labra2012_rock.toml \
  --maps-dir out/quickstart/maps --output out/quickstart --name labra_rock
