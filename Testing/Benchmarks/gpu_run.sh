#!/usr/bin/env bash
# On an NVIDIA GPU machine without ParaView or OpenCL packages: unpack the
# Debian 12 .deb files carried in .gpu/ (ignored by git; put there beforehand:
# clinfo, ocl-icd-libopencl1, ocl-icd-opencl-dev, opencl-c-headers, libimath
# and libopenexr with their -dev) into /tmp/ocl, register NVIDIA's OpenCL
# driver, build kernels/ alone, run the core tests on the GPU, benchmark
# every core, and soak the simulations.
#   Testing/Benchmarks/gpu_run.sh [OUT]      (OUT: where logs go, default ./gpu-out)
# DEVICES=K (on a machine with K GPUs, e.g. nvidia-h200-x2): also the cores that
# run as pieces (marked * in graupel-bench --help) with --devices 1 and K at
# DEVICE_SIZES (default 8192 16384), for both rain runoff flow models, after a
# --verify run at 512^2 (any bit of difference from one GPU fails it); DEVICES_ONLY=1
# skips the core tests and the one-device benchmarks. Results: $OUT/bench_devices.txt.
set -uo pipefail
cd "$(dirname "$(readlink -f "$0")")/../.."
OUT=${1:-${OUT:-gpu-out}}
mkdir -p "$OUT" /tmp/ocl /etc/OpenCL/vendors
for f in .gpu/*.deb; do dpkg -x "$f" /tmp/ocl; done
echo libnvidia-opencl.so.1 > /etc/OpenCL/vendors/nvidia.icd
export CPATH=/tmp/ocl/usr/include LIBRARY_PATH=/tmp/ocl/usr/lib/x86_64-linux-gnu
export LD_LIBRARY_PATH=/tmp/ocl/usr/lib/x86_64-linux-gnu:/usr/local/nvidia/lib64:${LD_LIBRARY_PATH:-}
export CMAKE_PREFIX_PATH=/tmp/ocl/usr
/tmp/ocl/usr/bin/clinfo -l | tee "$OUT/clinfo.txt"
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee -a "$OUT/clinfo.txt"
cmake -S kernels -B build-gpu -DCMAKE_BUILD_TYPE=Release >"$OUT/configure.log" 2>&1 &&
  cmake --build build-gpu -j"$(nproc)" >"$OUT/build.log" 2>&1 || { tail -40 "$OUT/build.log"; exit 1; }
# DEVICES=K: the grid split over K GPUs in one process (graupel-bench --devices).
if [ -n "${DEVICES:-}" ]; then
  SPLIT=$(build-gpu/graupel-bench --help | sed -n '/^cores:/,$p' | awk 'NR > 1 && $2 == "*" {print $1}')
  for core in ${SPLIT_CORES:-$SPLIT}; do
    for model in 1 0; do # rain runoff: local inertial, shallow water (other cores ignore it)
      GRAUPEL_BENCH_FLOW_MODEL=$model GRAUPEL_DEVICE=gpu build-gpu/graupel-bench --core "$core" \
        --size 512 --steps 20 --devices "$DEVICES" --verify 2>&1 |
        tee -a "$OUT/bench_devices.txt" | grep -E '^(verify|note|graupel-bench)'
      for n in ${DEVICE_SIZES:-8192 16384}; do
        for k in 1 "$DEVICES"; do
          GRAUPEL_BENCH_FLOW_MODEL=$model GRAUPEL_DEVICE=gpu build-gpu/graupel-bench --core "$core" \
            --size "$n" --steps ${STEPS:-50} --devices "$k" 2>&1 |
            tee -a "$OUT/bench_devices.txt" | tail -1
        done
      done
    done
  done
  [ -n "${DEVICES_ONLY:-}" ] && exit 0
fi
# The core tests on the GPU (test_procedural_terrain also compares the GPU with PoCL).
(cd build-gpu && GRAUPEL_DEVICE=gpu ctest -L core -LE memcheck --output-on-failure) \
  >"$OUT/ctest_gpu.log" 2>&1; tail -15 "$OUT/ctest_gpu.log"
# Every core graupel-bench knows (its registry, from kernels/cores.cmake) unless CORES names some.
CORES=${CORES:-$(build-gpu/graupel-bench --help | sed -n '/^cores:/,$p' | awk 'NR > 1 {print $1}')}
for core in $CORES; do
  for n in ${SIZES:-1024 2048 4096 8192}; do
    GRAUPEL_DEVICE=gpu build-gpu/graupel-bench --core "$core" --size "$n" --steps ${STEPS:-50} \
      2>&1 | tee -a "$OUT/bench_gpu.txt" | tail -1
  done
  GRAUPEL_DEVICE=cpu build-gpu/graupel-bench --core "$core" --size 1024 --steps 10 \
    2>&1 | tee -a "$OUT/bench_pocl_host.txt" | tail -1
done
# SOAK=N: N steps of each simulation's soak on the GPU (SOAK_CORES picks them).
if [ -n "${SOAK:-}" ]; then
  for core in ${SOAK_CORES:-rain_runoff snow_deformation}; do
    GRAUPEL_DEVICE=gpu build-gpu/Testing/C/test_soak "$core" "$SOAK" 2>&1 |
      tee "$OUT/soak_${core}_gpu.txt" | tail -3
  done
fi
