/* The rain_runoff program's shallow-water model, fused stages in tiles: a part
 * of rain_runoff_sw.cl, which inlines it here (see that file for the model). */

/* --------------------------------- shallow water, fused stages in tiles
 *
 * The fused path (gr_rain_runoff_set_sw_fused): each stage of Heun's method
 * in one pass over the grid's tiles (two launches: the interior's tiles,
 * rain_runoff_sw_inner1 and 2, and the rim's, rain_runoff_sw_stage1 and 2),
 * in place of sw_prep, faces, update and edges, with the same inline functions on
 * the same floats, so the same bits. A work-group owns a tile of
 * get_local_size(0) x get_local_size(1) cells: it gathers the stage's points
 * of the tile and two cells either side of it (the limited reconstruction's
 * reach; the corners are not needed) into local memory (stage 1 makes them
 * from the state, rain and infiltration as sw_prep does; stage 2 from h1,
 * qu1, qv1, the velocities as stage 1 would have stored them), computes its
 * tile's faces there (each face once: an x-face and a y-face per cell, one
 * more column and row; each face also keeps its high cell's slopes, which
 * the update takes instead of reconstructing the cell again), then updates its cells and books the
 * rim's edge flows. Points and faces never go to global memory: per cell a step reads the state,
 * bed and stage (h, qu, qv, b; h1, qu1, qv1, dh1, h_comp) and writes the stage and the state. The
 * local array `tile` holds the points ((tx + 4) (ty + 4) float4s: h, b, u, v) and six planes of
 * x-faces ((tx + 1) ty) and of y-faces (tx (ty + 1)): fh, fmL, fmR, ft and the high cell's sh,
 * se. */

/* Point p of the tile (h, b, u, v in one float4: one local-memory access
 * instead of four, which counted on GPUs, where the stages' time is their
 * instructions) as a line's point along x (normal u) or, xs 0, along y
 * (normal v). */
GR_INLINE gr_sw_pt gr_sw_tile_pt(__local const float4 *restrict tp, int p, bool xs) {
  float4 v = tp[p];
  gr_sw_pt q;
  q.h = v.x;
  q.b = v.y;
  q.un = xs ? v.z : v.w;
  q.ut = xs ? v.w : v.z;
  q.abi = 0.0f;
  return q;
}

/* Items t = start, start + wg, ... below n, one a work-item (start: the
 * work-item's first, below wg): a test instead of a loop where n <= wg,
 * which a GPU's program knows (the tile's size a constant there), so the
 * compiler need not keep a loop and a second copy of its body that never
 * runs. */
#define GR_SW_EACH(t, start, n, wg, stmt)                                                          \
  do {                                                                                             \
    if ((n) <= (wg)) {                                                                             \
      int t = (start);                                                                             \
      if (t < (n)) {                                                                               \
        stmt;                                                                                      \
      }                                                                                            \
    } else {                                                                                       \
      for (int t = (start); t < (n); t += (wg)) {                                                  \
        stmt;                                                                                      \
      }                                                                                            \
    }                                                                                              \
  } while (0)

/* Halo point t of a tile of tx x ty cells, as (*a, *e) of its local array:
 * the rows below and above the tile (4 tx points, t < 4 tx), then the
 * columns left and right of it (4 ty); the corners are never read. Both
 * divisions are by a constant on GPUs (unsigned: shifts for sides that
 * are powers of two); one by a side selected at run time took some 30
 * instructions of integer division on the H200. */
GR_INLINE void gr_sw_halo_at(uint t, uint tx, uint ty, int *a, int *e) {
  bool row = t < 4 * tx;
  uint u = row ? t : t - 4 * tx, r = row ? u / tx : u / ty;
  uint o = 2 + u - r * (row ? tx : ty), far = r < 2 ? r : r + (row ? ty : tx);
  *a = (int)(row ? o : far);
  *e = (int)(row ? far : o);
}

/* The tile (*ti, *tj) of the rim's work-group r (rain_runoff_sw_stage*):
 * the tiles outside the interior ones (tiles: their columns x .. y - 1 and
 * rows z .. w - 1) of a grid of nti x ntj tiles, row by row: the rows
 * below the interior's, those above, then the rows between, each the
 * columns left and right of the interior's. */
GR_INLINE void gr_sw_rim_tile(int r, int nti, int ntj, int4 tiles, int *ti, int *tj) {
  int south = tiles.z * nti, north = (ntj - tiles.w) * nti, per = tiles.x + nti - tiles.y;
  int row = r < south ? 0 : (r < south + north ? tiles.w : tiles.z);
  int k = r < south ? r : (r < south + north ? r - south : r - south - north);
  int w = r < south + north ? nti : per;
  int e = k / w, a = k - e * w;
  *tj = row + e;
  *ti = r < south + north || a < tiles.x ? a : tiles.y + (a - tiles.x);
}

/* Point (a, e) of the tile's local array (pw points a row; its cell
 * (i0 - 2 + a, j0 - 2 + e)), 0 beyond the grid as gr_sw_point masks them:
 * stage 1 makes it from the state, rain and infiltration as sw_prep does,
 * stage 2 takes U1's velocities as stage 1 would have stored them. */
GR_INLINE void gr_sw_tile_point(GR_SW_CELL_ARGS, __local float4 *restrict tp, int pw, int i0,
                                int j0, int a, int e, const int stage) {
  int pi = i0 - 2 + a, pj = j0 - 2 + e;
  bool in = pi >= 0 && pi < nx && pj >= 0 && pj < ny;
  float ph = 0.0f, pb = 0.0f, pu = 0.0f, pv = 0.0f;
  if (in) {
    int q = pj * nx + pi;
    pb = b[q];
    if (stage == 1) {
      gr_sw_wet_point(GR_SW_CELL_PASS, q, &ph, &pu, &pv);
    } else {
      ph = h1[q];
      pu = gr_sw_velocity(ph, qu1[q]);
      pv = gr_sw_velocity(ph, qv1[q]);
    }
  }
  tp[e * pw + a] = (float4)(ph, pb, pu, pv);
}

/* The tile's face (a, e) along x (xs: between cells a - 1 and a of row e)
 * or along y (between rows e - 1 and e of column a), from the points, its
 * six values (gr_sw_line_face's fh, fmL, fmR, ft, sh, se) written to out
 * and the five planes after it (plane floats apart), at a + e (tx + 1) for
 * an x-face, a + e tx for a y-face. An interior tile (inner: its faces all
 * two cells or more inside the grid) takes the face's expression without
 * the edges' cases (gr_sw_inner_flux); a rim tile's face beyond the grid
 * is computed from zeros and never read. */
GR_INLINE void gr_sw_tile_face(__local const float4 *restrict tp, __local float *restrict out,
                               int plane, int tx, int pw, int i0, int j0, int a, int e, int nx,
                               int ny, int bnd_w, int bnd_e, int bnd_s, int bnd_n, float lvl_w,
                               float lvl_e, float lvl_s, float lvl_n, float g, const bool xs,
                               const int inner) {
  int p = (e + 2) * pw + a + 2, step = xs ? 1 : pw; /* the high cell's point */
  gr_sw_pt q0 = gr_sw_tile_pt(tp, p - 2 * step, xs);
  gr_sw_pt q1 = gr_sw_tile_pt(tp, p - step, xs);
  gr_sw_pt q2 = gr_sw_tile_pt(tp, p, xs);
  gr_sw_pt q3 = gr_sw_tile_pt(tp, p + step, xs);
  float fh, fmL, fmR, ft, sh, se;
  if (inner)
    gr_sw_inner_flux(q0, q1, q2, q3, g, &fh, &fmL, &fmR, &ft, &sh, &se);
  else
    gr_sw_line_flux(q0, q1, q2, q3, xs ? i0 + a : j0 + e, xs ? nx : ny, xs ? bnd_w : bnd_s,
                    xs ? bnd_e : bnd_n, xs ? lvl_w : lvl_s, xs ? lvl_e : lvl_n, g, &fh, &fmL, &fmR,
                    &ft, &sh, &se);
  int u = a + e * (xs ? tx + 1 : tx);
  GR_SW_PUT_FACE(out, u, plane, fh, fmL, fmR, ft, sh, se);
}

/* One stage for the tiles of the interior (inner: its tile columns tiles.x
 * .. tiles.y - 1 and rows tiles.z .. tiles.w - 1, one work-group each), or
 * for those of the rim (a line of work-groups, gr_sw_rim_tile). Each
 * work-item makes its own cell's point and computes its cell's west and
 * south faces. The rest of the tile's points (the two rows below and above
 * it, the two columns left and right; the corners are never read) go one
 * a work-item to the first work-items: on the H200 (tile 32 x 8) five
 * warps make two points and three make one, where before the rows' points
 * on two warps and the columns' on a third made three each while the
 * others waited at the barrier. The rest of the faces (the east column
 * and the north row) go to work-items from both ends of the work-group.
 * Every index follows from the work-item's own or from a division by the
 * tile's size, a constant on GPUs (on the H200 the loops over a flat
 * index, divided by the tile's run-time width, took a fifth of the faces'
 * instructions in index arithmetic and selections of planes). The update
 * loads everything it reads of global memory first (gr_sw_cell_read):
 * read where they are used, the flood maps and the infiltrated water
 * waited on the new state's stores. The H200 at 4096^2, ms a step: 1.059
 * before, 1.009 with the points spread, 1.012 with the loads first, 1.003
 * with both, 0.976 with the halo's indices by constant divisions and no
 * loop (gr_sw_halo_at, GR_SW_EACH; the same bits). */
GR_INLINE void gr_sw_fused(GR_SW_CELL_ARGS, float lvl_w, float lvl_e, float lvl_s, float lvl_n,
                           __local float4 *restrict tile, int4 tiles, const int stage,
                           const int inner) {
  int lx = get_local_id(0), ly = get_local_id(1);
  /* The tile's size, a constant where the program is built for it (GPUs:
   * GR_SW_TILE_X, GR_SW_TILE_Y), so that every index and loop bound of the
   * tile is one: on the H200 at 4096^2 1.12 -> 1.07 ms a step, and the
   * interior's kernels no longer spill. */
#ifdef GR_SW_TILE_X
  const int tx = GR_SW_TILE_X, ty = GR_SW_TILE_Y;
#else
  int tx = get_local_size(0), ty = get_local_size(1);
#endif
  int ti = tiles.x + get_group_id(0), tj = tiles.z + get_group_id(1);
  if (!inner)
    gr_sw_rim_tile(get_group_id(0), (nx + tx - 1) / tx, (ny + ty - 1) / ty, tiles, &ti, &tj);
  int i0 = ti * tx, j0 = tj * ty;
  int i = i0 + lx, j = j0 + ly, lid = ly * tx + lx, wg = tx * ty;
  int pw = tx + 4, np = pw * (ty + 4), nfx = (tx + 1) * ty, nfy = tx * (ty + 1);
  /* The points first, as float4s: a local float4 argument is aligned for
   * them (a float one need not be: NVIDIA's failed on float4 reads). */
  __local float4 *tp = tile;
  __local float *xh = (__local float *)(tile + np), *xl = xh + nfx, *xr = xl + nfx, *xt = xr + nfx;
  __local float *xsh = xt + nfx, *xse = xsh + nfx;
  __local float *yh = xse + nfx, *yl = yh + nfy, *yr = yl + nfy, *yt = yr + nfy;
  __local float *ysh = yt + nfy, *yse = ysh + nfy;
  gr_sw_tile_point(GR_SW_CELL_PASS, tp, pw, i0, j0, lx + 2, ly + 2, stage);
  /* The halo's points, one a work-item from the first on
   * (gr_sw_halo_at). */
  int a, e;
  GR_SW_EACH(t, lid, 4 * (tx + ty), wg, gr_sw_halo_at(t, tx, ty, &a, &e);
             gr_sw_tile_point(GR_SW_CELL_PASS, tp, pw, i0, j0, a, e, stage));
  barrier(CLK_LOCAL_MEM_FENCE);
#define GR_SW_TILE_FACE(a, e, xs)                                                                  \
  gr_sw_tile_face(tp, xs ? xh : yh, xs ? nfx : nfy, tx, pw, i0, j0, a, e, nx, ny, bnd_w, bnd_e,    \
                  bnd_s, bnd_n, lvl_w, lvl_e, lvl_s, lvl_n, g, xs, inner)
  GR_SW_TILE_FACE(lx, ly, true);
  GR_SW_TILE_FACE(lx, ly, false);
  GR_SW_EACH(t, lid, ty, wg, GR_SW_TILE_FACE(tx, t, true));
  GR_SW_EACH(t, wg - 1 - lid, tx, wg, GR_SW_TILE_FACE(t, ty, false));
#undef GR_SW_TILE_FACE
  /* Everything the update reads of global memory, loaded before it stores
   * anything (gr_sw_cell_read). The cell's index is taken before the
   * barrier and the loads come after it: on the H200 that form made the
   * step 1.035 -> 1.006 ms at 4096^2 against the index taken after the
   * barrier (the same loads; NVIDIA's compiler scheduled them worse). */
  bool own = i < nx && j < ny;
  int c = own ? gr_idx(i, j, nx) : 0;
  float suc = 0.0f, svc = 0.0f;
  gr_sw_cell_in in = {0.0f};
  barrier(CLK_LOCAL_MEM_FENCE);
  if (!own)
    return;
  suc = stage == 1 ? qu[c] : qu1[c];
  svc = stage == 1 ? qv[c] : qv1[c];
  in = gr_sw_cell_read(GR_SW_CELL_PASS, c, stage);
  int p = (ly + 2) * pw + lx + 2;
  gr_sw_pt x2 = gr_sw_tile_pt(tp, p, true);
  int fw = ly * (tx + 1) + lx, fs = ly * tx + lx, fn = fs + tx;
  gr_sw_update_cell(GR_SW_CELL_PASS, i, j, x2, xsh[fw], xse[fw], ysh[fs], yse[fs], xh[fw], xr[fw],
                    xt[fw], xh[fw + 1], xl[fw + 1], xt[fw + 1], yh[fs], yr[fs], yt[fs], yh[fn],
                    yl[fn], yt[fn], suc, svc, 1, in, stage, 0);
  /* Half of the stage's edge flows, as rain_runoff_sw_edges books them
   * after the update (the rim's tiles hold every edge cell). */
  if (!inner && (i == 0 || j == 0 || i == nx - 1 || j == ny - 1)) {
    float olx = i > 0 ? 0.0f : -xh[fw], ohx = i < nx - 1 ? 0.0f : xh[fw + 1];
    float oly = j > 0 ? 0.0f : -yh[fs], ohy = j < ny - 1 ? 0.0f : yh[fn];
    gr_rain_runoff_book_edges(outflow, outflow_comp, inflow, inflow_comp, c, 0.5f * dt, inv_dx,
                              inv_dy, olx, ohx, oly, ohy);
  }
}

/* Each stage is two kernels: its interior tiles (rain_runoff_sw_inner*,
 * tiles.x .. tiles.y - 1 by tiles.z .. tiles.w - 1 work-groups) and the
 * rest, the rim (rain_runoff_sw_stage*, a line of work-groups). The
 * interior's kernel carries none of the edges' cases, so it needs fewer
 * registers: on the H200, capped at 32 a work-item, one kernel for every
 * tile spilled 80-92 bytes, the interior's kernel spills none (4096^2:
 * 1.55 ms a step with one kernel, 1.51 with two). All take GR_SW_STEP_ARGS (the host
 * binds the same table), the tiles and the tile's local memory: 4 (tx + 4)
 * (ty + 4) + 6 (tx + 1) ty + 6 tx (ty + 1) floats. */
#ifdef GR_SW_TILE_X
#define GR_SW_TILE_ATTR __attribute__((reqd_work_group_size(GR_SW_TILE_X, GR_SW_TILE_Y, 1)))
#else
#define GR_SW_TILE_ATTR
#endif
#define GR_SW_FUSED_KERNEL(name, stage, inner)                                                     \
  __kernel GR_SW_TILE_ATTR void name(GR_SW_STEP_ARGS, int4 tiles, __local float4 *restrict tile) { \
    gr_sw_fused(GR_SW_CELL_PASS, lvl_w, lvl_e, lvl_s, lvl_n, tile, tiles, stage, inner);           \
  }
GR_SW_FUSED_KERNEL(rain_runoff_sw_stage1, 1, 0)
GR_SW_FUSED_KERNEL(rain_runoff_sw_stage2, 2, 0)
GR_SW_FUSED_KERNEL(rain_runoff_sw_inner1, 1, 1)
GR_SW_FUSED_KERNEL(rain_runoff_sw_inner2, 2, 1)
