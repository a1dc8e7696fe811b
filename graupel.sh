#!/usr/bin/env bash
# Graupel's one entry point for set-up, demo and tests.
#
#   ./graupel.sh demo   install what is missing, build, run Examples/demo_terrain.py -> out/
#   ./graupel.sh test   install what is missing, build all three configurations, run ctest
#   ./graupel.sh build  install what is missing and build the plugin only
#   ./graupel.sh soak   the long soak runs (ctest label "soak", kept out of "test")
#
# Builds: build/ (ParaView plugin + Python module), build-vtk/ (the VTK module alone
# against Debian's VTK 9.1, for plain python3), build-core/ (kernels/ on its own, as on
# a GPU machine without ParaView; its tests include valgrind memcheck), build-asan/
# (kernels/ with clang, AddressSanitizer + UndefinedBehaviorSanitizer, and libFuzzer
# harnesses). Everything is incremental: a second run is quick.
set -euo pipefail
cd "$(dirname "$(readlink -f "$0")")"
ROOT=$PWD
JOBS=$(nproc 2>/dev/null || echo 2)

PACKAGES=(
  paraview paraview-dev python3-paraview python3-numpy
  pocl-opencl-icd ocl-icd-opencl-dev opencl-headers clinfo
  libopenexr-dev libglm-dev xvfb xauth cmake g++ make clang-format
  # hardening: sanitizers and libFuzzer (clang's runtime), valgrind
  clang libclang-rt-14-dev valgrind
  qtbase5-dev libqt5svg5-dev qttools5-dev qtxmlpatterns5-dev-tools
  libqt5x11extras5-dev libqt5opengl5-dev
  # find_package(ParaView) also needs these development files:
  libopenmpi-dev libdouble-conversion-dev liblz4-dev libutfcpp-dev
  libjsoncpp-dev libpugixml-dev libtbb-dev
  # the VTK-alone build: VTK 9.1's libraries (its -dev files are unpacked below)
  libvtk9.1 libvtk9.1-qt
  # the real DEM in Data/ is checked against its source, shipped here
  python-matplotlib-data
)

as_root() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }

ensure_packages() {
  local missing=() p
  for p in "${PACKAGES[@]}"; do
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

configure_and_build() { # dir, source, extra cmake args...
  local dir=$1 src=$2; shift 2
  if [ ! -f "$dir/CMakeCache.txt" ]; then
    # Debian's python3 (the one pvpython and python3-vtk9 use), not whatever
    # python3 comes first on PATH.
    cmake -S "$src" -B "$dir" -DCMAKE_BUILD_TYPE=Release -DGRAUPEL_WERROR=ON \
      -DPython3_EXECUTABLE=/usr/bin/python3 "$@"
  fi
  cmake --build "$dir" -j"$JOBS"
}

build_plugin() { configure_and_build build . ; }
build_vtk() {
  ensure_vtk_deps
  configure_and_build build-vtk . -DGRAUPEL_BUILD_PLUGIN=OFF \
    -DVTK_DIR="$VTK_DEPS/root/usr/lib/x86_64-linux-gnu/cmake/vtk-9.1" \
    -DGRAUPEL_VTK_DEPS="$VTK_DEPS/root"
}
build_core() { configure_and_build build-core kernels ; }
build_asan() {
  CC=clang configure_and_build build-asan kernels -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DGRAUPEL_SANITIZE=ON -DGRAUPEL_FUZZ=ON
}

cmd=${1:-}
case "$cmd" in
  build)
    ensure_packages
    build_plugin
    ;;
  demo)
    ensure_packages
    build_plugin
    mkdir -p out
    PYTHONPATH="$ROOT/build/lib/python3/site-packages${PYTHONPATH:+:$PYTHONPATH}" \
    PV_PLUGIN_PATH="$ROOT/build/lib/paraview-5.11/plugins/Graupel" \
      xvfb-run -a -s "-screen 0 1280x1024x24" pvbatch Examples/demo_terrain.py --out out
    ;;
  test)
    ensure_packages
    build_plugin
    build_vtk
    build_core
    build_asan
    status=0
    for dir in build build-vtk build-core build-asan; do
      echo "graupel: ctest in $dir"
      (cd "$dir" && ctest --output-on-failure -j"$JOBS" -LE soak ${CTEST_ARGS:-}) || status=1
    done
    exit $status
    ;;
  soak)
    ensure_packages
    build_core
    cd build-core && ctest --output-on-failure -L soak ${CTEST_ARGS:-}
    ;;
  *)
    sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
    ;;
esac
