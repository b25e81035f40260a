#!/usr/bin/env bash
# The ParaView set-up under test (issue 14): a small 3D flat-jointed UCS is run with the built
# rocklab, viz/rocklab_paraview.py renders its end headless with ParaView's own pvbatch, and
# check_png.py checks the picture (drawn, specimen filling the frame, cracks, legends), and the
# same for its --section view and its --events view (the acoustic-emission events as spheres).
# Run by .ci/run after the README's test command (needs build/rocklab). Units of the run: SI.
#
# Debian's python3-paraview conflicts with python3-vtk9 (pulled in by libvtk9-dev), so this
# installs paraview and unpacks python3-paraview into a folder of its own; pvbatch needs an X
# display, given by xvfb-run.
set -euo pipefail
cd "$(dirname "$0")/../.."
pv=${ROCKLAB_PVPYTHON_DIR:-/tmp/rocklab-pvpython}
if ! command -v pvbatch >/dev/null || ! command -v xvfb-run >/dev/null; then
  apt-get install -y --no-install-recommends paraview xvfb xauth python3-numpy \
    python3-matplotlib python3-mpi4py python3-twisted python3-autobahn python3-six
fi
if [ ! -d "$pv/usr/lib/python3/dist-packages/paraview" ]; then
  deb=$(mktemp -d)
  (cd "$deb" && apt-get download python3-paraview)
  dpkg -x "$deb"/python3-paraview_*.deb "$pv"
fi
export PYTHONPATH="$pv/usr/lib/python3/dist-packages${PYTHONPATH:+:$PYTHONPATH}"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
./build/rocklab test tests/render/ucs_3d_small.json -o "$out/ucs" -q
png=${ROCKLAB_RENDER_PNG:-$out/ucs.png}
# One X server for every picture (starting one per pvbatch raced: an xvfb-run once failed to
# start its server right after the previous one stopped). -noreset: by default Xvfb resets when its
# last client leaves, and a pvbatch connecting during that reset aborts with "bad X server
# connection" (seen in CI between the two pictures). The section view: faced grains behind the
# axial plane, coloured by their non-affine strain.
export out png
xvfb-run -a -s "-screen 0 1600x1200x24 -noreset" bash -c '
  set -e
  pvbatch viz/rocklab_paraview.py "$out/ucs" --png "$png" --size 1200x900
  pvbatch tests/render/check_png.py "$png"
  pvbatch viz/rocklab_paraview.py "$out/ucs" --section --png "$out/section.png" --size 1200x900
  pvbatch tests/render/check_png.py "$out/section.png"
  pvbatch viz/rocklab_paraview.py "$out/ucs" --events --png "$out/events.png" --size 1200x900
  pvbatch tests/render/check_png.py "$out/events.png"'
