/* How far each cell is from the nearest occupied cell, so that the ray marchers can jump
 * over empty space in one go instead of testing it sample by sample.
 *
 * The distance is Chebyshev (the largest per-axis difference of cell indices), which is what
 * a jump needs: when a sample's cell has radius r, every cell whose indices differ from its
 * own by at most r - 1 on each axis is empty, so the ray may skip every sample before it
 * leaves that box of cells (field_lattice_skip). The transform is separable: per row along x,
 * then min over y of max(|dy|, row distance), then the same over z. */
#include <string.h>

#include "field_internal.h"

/* One pass along an axis: out[i] = min over j of max(|i - j|, in[j]) for the n cells
 * in[0], in[stride], ..., capped at FIELD_MAX_RADIUS. Only j closer than the best so far can
 * improve it, so the search stops there. */
static void min_max_pass(const uint8_t *in, uint8_t *out, int n, size_t stride)
{
    for (int i = 0; i < n; i++) {
        int best = in[(size_t)i * stride];
        for (int d = 1; d < best; d++) {
            if (i - d >= 0 && in[(size_t)(i - d) * stride] < best)
                best = d > in[(size_t)(i - d) * stride] ? d : in[(size_t)(i - d) * stride];
            if (i + d < n && in[(size_t)(i + d) * stride] < best)
                best = d > in[(size_t)(i + d) * stride] ? d : in[(size_t)(i + d) * stride];
        }
        out[(size_t)i * stride] = (uint8_t)best;
    }
}

void vf__field_grid_update_empty_radius(field_grid *g, uint8_t *scratch)
{
    const int nx = g->cells[0], ny = g->cells[1], nz = g->cells[2];
    const size_t row = (size_t)nx, slice = row * (size_t)ny;
    uint8_t *r = g->empty_radius;
    /* along x: 0 in occupied cells, else the distance to the nearest one in the row */
#pragma omp parallel for schedule(static)
    for (int zy = 0; zy < ny * nz; zy++) {
        size_t first = (size_t)zy * row;
        int run = FIELD_MAX_RADIUS;
        for (int x = 0; x < nx; x++) {
            run = field_cell_occupied(g, first + x) ? 0 : run < FIELD_MAX_RADIUS ? run + 1 : run;
            r[first + x] = (uint8_t)run;
        }
        run = FIELD_MAX_RADIUS;
        for (int x = nx - 1; x >= 0; x--) {
            run = r[first + x] == 0 ? 0 : run < FIELD_MAX_RADIUS ? run + 1 : run;
            r[first + x] = r[first + x] < run ? r[first + x] : (uint8_t)run;
        }
    }
    /* along y, then along z */
#pragma omp parallel for schedule(static)
    for (int zx = 0; zx < nz * nx; zx++) {
        size_t first = (size_t)(zx / nx) * slice + (size_t)(zx % nx);
        min_max_pass(r + first, scratch + first, ny, row);
    }
#pragma omp parallel for schedule(static)
    for (size_t yx = 0; yx < slice; yx++)
        min_max_pass(scratch + yx, r + yx, nz, slice);
}
