# Graupel's cores, one name a line: the one list a new core joins (the
# other two are the filter classes in Filters/CMakeLists.txt and the proxy
# XML in Plugin/CMakeLists.txt). From each name <core>, kernels/CMakeLists.txt
# takes src/<core>.c (and any src/<core>_*.c), cl/<core>.cl,
# include/graupel/<core>.h and bench/bench_<core>.c, and writes graupel_cores.h (GRAUPEL_CORE_LIST, which
# graupel-params and graupel-bench iterate); Testing/C declares test_<core>.c
# (with any test_<core>_*.c; options from test_<core>.cmake if present) and Testing/Fuzz builds
# fuzz_<core>_params.c if present. Keep it sorted: graupel-params prints
# the cores in this order.
set(GRAUPEL_CORES
  particles
  procedural_terrain
  rain_runoff
  sky
  snow_accumulation
  snow_deformation
  snow_melt
  terrain_analysis
  water_surface
)
