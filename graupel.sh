#!/usr/bin/env bash
# Graupel's one entry point for set-up, demo and tests.
#
#   ./graupel.sh demo   install what the demo needs, build the plugin, run
#                       Examples/demo_terrain.py, demo_snow_deformation.py and
#                       demo_snow_accumulation.py -> out/
#   ./graupel.sh test   install what is missing, build all four configurations, run ctest
#   ./graupel.sh build  install what the plugin needs and build the plugin only
#   ./graupel.sh soak   the long soak runs (ctest label "soak", kept out of "test")
#
# The four configurations are the presets of CMakePresets.json: plugin -> build/
# (ParaView plugin + Python module), vtk -> build-vtk/ (the VTK module alone against
# Debian's VTK 9.1, for plain python3), core -> build-core/ (kernels/ on its own, as
# on a GPU machine without ParaView; its tests include valgrind memcheck), asan ->
# build-asan/ (kernels/ with clang, AddressSanitizer + UndefinedBehaviorSanitizer, and
# libFuzzer harnesses). `cmake --preset` runs every time, so a changed option reaches
# an existing tree; everything else is incremental: a second run is quick.
set -euo pipefail
cd "$(dirname "$(readlink -f "$0")")"
ROOT=$PWD
JOBS=$(nproc 2>/dev/null || echo 2)

# What building the plugin and running the demo need.
PACKAGES=(
  paraview paraview-dev python3-paraview python3-numpy
  pocl-opencl-icd ocl-icd-opencl-dev opencl-headers clinfo
  libopenexr-dev libglm-dev xvfb xauth cmake g++ make
  # GIS rasters (GeoTIFF, ASCII grids) in and GeoTIFF out
  libgdal-dev
  qtbase5-dev libqt5svg5-dev qttools5-dev qtxmlpatterns5-dev-tools
  libqt5x11extras5-dev libqt5opengl5-dev
  # find_package(ParaView) also needs these development files:
  libopenmpi-dev libdouble-conversion-dev liblz4-dev libutfcpp-dev
  libjsoncpp-dev libpugixml-dev libtbb-dev
)
# What only the tests need.
TEST_PACKAGES=(
  clang-format
  # hardening: sanitizers and libFuzzer (clang's runtime), valgrind
  clang libclang-rt-14-dev valgrind
  # the VTK-alone build: VTK 9.1's libraries (its -dev files are unpacked below)
  libvtk9.1 libvtk9.1-qt
  # the real DEM in Data/ is checked against its source, shipped here
  python-matplotlib-data
  # GIS files made and checked from outside Graupel (gdalwarp, gdalinfo, osgeo)
  gdal-bin python3-gdal
  # the GUI tests drive the mouse and read the screen
  xdotool imagemagick
)

as_root() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }

ensure_packages() { # package names...
  local missing=() p
  for p in "$@"; do
    case "$p" in \#*) continue ;; esac
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" \
      || missing+=("$p")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "graupel: installing ${missing[*]}"
    as_root apt-get update -q
    as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -q \
      --no-install-recommends "${missing[@]}"
  fi
}

# Debian 12's python3-vtk9 (which libvtk9-dev depends on) conflicts with
# python3-paraview: both ship the Python package vtkmodules. So the VTK-alone
# build uses VTK 9.1's development files unpacked into build-vtk/deps instead
# of installed; the plugin build keeps ParaView's own VTK.
VTK_DEPS=$ROOT/build-vtk/deps
VTK_DEBS=(libvtk9-dev python3-vtk9 libvtk9.1 libvtk9.1-qt libvtk9-java vtk9)
ensure_vtk_deps() {
  local stamp=$VTK_DEPS/.unpacked
  [ -f "$stamp" ] && return 0
  mkdir -p "$VTK_DEPS/debs"
  ( cd "$VTK_DEPS/debs" && { apt-get download "${VTK_DEBS[@]}" \
      || { as_root apt-get update -q && apt-get download "${VTK_DEBS[@]}"; }; } )
  local deb
  for deb in "$VTK_DEPS"/debs/*.deb; do dpkg -x "$deb" "$VTK_DEPS/root"; done
  touch "$stamp"
}

# One configuration: configure (every time: cheap, and a changed preset option
# reaches the cache) and build.
build_preset() { # preset
  local preset=$1 dir
  dir=$(preset_dir "$preset")
  # A tree configured from another source folder (build-core and build-asan
  # were once configured from kernels/) cannot be reconfigured: start its
  # cache afresh (the objects are rebuilt; build-vtk/deps stays).
  if [ -f "$dir/CMakeCache.txt" ] &&
    ! grep -qx "CMAKE_HOME_DIRECTORY:INTERNAL=$ROOT" "$dir/CMakeCache.txt"; then
    echo "graupel: $dir was configured from another source folder; configuring it afresh"
    rm -rf "$dir/CMakeCache.txt" "$dir/CMakeFiles"
  fi
  [ "$preset" = vtk ] && ensure_vtk_deps
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset" -j"$JOBS"
}
preset_dir() {
  case "$1" in
    plugin) echo build ;; vtk) echo build-vtk ;; core) echo build-core ;; asan) echo build-asan ;;
  esac
}
PRESETS=(plugin vtk core asan)

cmd=${1:-}
case "$cmd" in
  build)
    ensure_packages "${PACKAGES[@]}"
    build_preset plugin
    ;;
  demo)
    ensure_packages "${PACKAGES[@]}"
    build_preset plugin
    mkdir -p out
    PYTHONPATH="$ROOT/build/lib/python3/site-packages${PYTHONPATH:+:$PYTHONPATH}" \
    PV_PLUGIN_PATH="$ROOT/build/lib/paraview-5.11/plugins/Graupel" \
      xvfb-run -a -s "-screen 0 1280x1024x24" pvbatch Examples/demo_terrain.py --out out
    # A wheel rolling through snow: out/snow_deformation_t1..t3.png (a third, two
    # thirds and the end of its crossing), snow_deformation_close.png and .vti.
    PYTHONPATH="$ROOT/build/lib/python3/site-packages${PYTHONPATH:+:$PYTHONPATH}" \
    PV_PLUGIN_PATH="$ROOT/build/lib/paraview-5.11/plugins/Graupel" \
      xvfb-run -a -s "-screen 0 1280x1024x24" pvbatch Examples/demo_snow_deformation.py --out out
    # Snow on a hut and trees under wind, then a sledge across it:
    # out/snow_accumulation.png (the snowfall: depth, lee-side shadows, bare
    # ground under the roof, snow caps), snow_accumulation_sledge.png (the
    # sledge's trail) and snow_accumulation.vti.
    PYTHONPATH="$ROOT/build/lib/python3/site-packages${PYTHONPATH:+:$PYTHONPATH}" \
    PV_PLUGIN_PATH="$ROOT/build/lib/paraview-5.11/plugins/Graupel" \
      xvfb-run -a -s "-screen 0 1280x1024x24" pvbatch Examples/demo_snow_accumulation.py --out out
    ;;
  test)
    ensure_packages "${PACKAGES[@]}" "${TEST_PACKAGES[@]}"
    for preset in "${PRESETS[@]}"; do build_preset "$preset"; done
    status=0
    for preset in "${PRESETS[@]}"; do
      echo "graupel: ctest --preset $preset"
      ctest --preset "$preset" -j"$JOBS" ${CTEST_ARGS:-} || status=1
    done
    exit $status
    ;;
  soak)
    ensure_packages "${PACKAGES[@]}"
    build_preset core
    ctest --preset soak ${CTEST_ARGS:-} || status=1
    build_preset plugin
    ctest --preset soak-plugin ${CTEST_ARGS:-} || status=1
    exit ${status:-0}
    ;;
  *)
    sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
    ;;
esac
