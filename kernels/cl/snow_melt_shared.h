/* Constants of the snow melt core that the host (snow_melt*.c) and the
 * device (snow_melt.cl) must agree on: written once here, included by both.
 * Plain preprocessor definitions only, valid C11 and OpenCL C. */
#ifndef GRAUPEL_CL_SNOW_MELT_SHARED_H
#define GRAUPEL_CL_SNOW_MELT_SHARED_H

/* The state's fixed point: water equivalents in integers of 2^-32 m. */
#define GR_SNOW_MELT_UNITS_PER_M 4294967296.0

/* The accumulators a point keeps (64-bit integers of the state's unit),
 * GR_SNOW_MELT_ACCS of them, stored acc[q * n + c]: */
#define GR_SNOW_MELT_ACC_SNOW 0          /* precipitation as snow */
#define GR_SNOW_MELT_ACC_RAIN 1          /* precipitation as rain */
#define GR_SNOW_MELT_ACC_MELT 2          /* melt */
#define GR_SNOW_MELT_ACC_REFROZEN 3      /* refreezing */
#define GR_SNOW_MELT_ACC_RELEASED 4      /* release */
#define GR_SNOW_MELT_ACC_MARK_MELT 5     /* melt since the mark */
#define GR_SNOW_MELT_ACC_MARK_RELEASED 6 /* release since the mark */
#define GR_SNOW_MELT_ACCS 7

/* The ledger's reduction: 8 quantities (frozen, liquid, then accumulators
 * 0 .. 4 and 6), each summed as two words, its value's bits above and below
 * bit 24 (so 2^32 points of up to 2^50 units never overflow). */
#define GR_SNOW_MELT_SUMS 8
#define GR_SNOW_MELT_WORDS 16
#define GR_SNOW_MELT_SPLIT_BITS 24

/* The sun's sub-steps: at most this long (s), and the records of one batch
 * of steps in the device's table, GR_SNOW_MELT_RECORD floats each: the unit
 * vector towards the sun (east, north, up), I0 (Rm/R)^2 (0 with the sun at
 * or below the horizon), 1 / cos Z, the azimuth in sectors (0 .. sectors),
 * the elevation (rad), unused. */
#define GR_SNOW_MELT_SUBSTEP_S 900.0
#define GR_SNOW_MELT_RECORD 8
#define GR_SNOW_MELT_TABLE_RECORDS 1024

/* The horizons' rays step over blocks of this many cells square whose
 * highest point cannot rise above the horizon found so far. */
#define GR_SNOW_MELT_BLOCK 16

/* What the derive kernel writes. */
#define GR_SNOW_MELT_DERIVE_DEPTH 0
#define GR_SNOW_MELT_DERIVE_DENSITY 1
#define GR_SNOW_MELT_DERIVE_SWE 2
#define GR_SNOW_MELT_DERIVE_LIQUID 3
#define GR_SNOW_MELT_DERIVE_MELT_RATE 4
#define GR_SNOW_MELT_DERIVE_RELEASE_RATE 5
#define GR_SNOW_MELT_DERIVE_RADIATION 6
#define GR_SNOW_MELT_DERIVE_RELEASED 7

#endif
