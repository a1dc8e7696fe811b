/* Constants of the rain runoff core that the host (rain_runoff.c) and the
 * device (rain_runoff.cl) must agree on: written once here, included by both.
 * Plain preprocessor definitions only, valid C11 and OpenCL C. */
#ifndef GRAUPEL_CL_RAIN_RUNOFF_SHARED_H
#define GRAUPEL_CL_RAIN_RUNOFF_SHARED_H

/* The weight of a face's own previous discharge against its neighbours'
 * (de Almeida et al. 2012; 1 is Bates et al. 2010 unchanged). The device
 * gets it as the float argument theta; the host's stable step uses it too. */
#define GR_RAIN_RUNOFF_THETA 0.8

/* A face shallower than this carries no flow (m). */
#define GR_RAIN_RUNOFF_DRY 1.0e-6f

/* Velocities are reported where a cell holds at least this much (m): a cell
 * that a step has just drained holds a film whose depth says nothing of
 * the flow that passed through it, and q / h there would be meaningless. */
#define GR_RAIN_RUNOFF_VELOCITY_DEPTH 1.0e-4f

/* The limiter leaves a cell this fraction short of empty, so that the float
 * rounding of the depth update can never take it below zero. */
#define GR_RAIN_RUNOFF_KEEP 0.999999f

/* The ledger's reduction (reduce.h): four fixed-point sums (stored,
 * infiltrated, outflow, inflow, in metres of depth over cells; two int64
 * words each) and one maximum (the deepest cell) per work-group. */
#define GR_RAIN_RUNOFF_SUMS 4

/* Edge kinds, the values of gr_boundary (graupel/rain_runoff.h), as the
 * kernels get them (bnd_w, bnd_e, bnd_s, bnd_n: scalar arguments; int4 ones
 * kept PoCL from vectorising the local inertial flux kernel, 2x slower). */
#define GR_RAIN_RUNOFF_B_OPEN 0
#define GR_RAIN_RUNOFF_B_CLOSED 1
#define GR_RAIN_RUNOFF_B_TRANSMISSIVE 2
#define GR_RAIN_RUNOFF_B_LEVEL 3
#define GR_RAIN_RUNOFF_MAXES 1

/* The optional inputs a program of rain_runoff.cl is built for, a bit each
 * (GR_RAIN_RUNOFF_INPUTS there): a rain map, a permeability map, sources
 * (inflows), no-data cells and a Manning map. */
#define GR_RAIN_RUNOFF_IN_RAIN 1
#define GR_RAIN_RUNOFF_IN_PERM 2
#define GR_RAIN_RUNOFF_IN_SRC 4
#define GR_RAIN_RUNOFF_IN_NODATA 8
#define GR_RAIN_RUNOFF_IN_N2 16
#define GR_RAIN_RUNOFF_IN_ALL 31

/* The flood-hazard rating's debris factor applies where the depth exceeds
 * this (m): FD2321/TR2 (HR Wallingford 2006, Table 3.1) gives DF = 0 up to
 * 0.25 m under every land use. */
#define GR_RAIN_RUNOFF_DEBRIS_DEPTH 0.25f

#endif
