/* Grid storage, trilinear resampling and the occupancy bitfield. */
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

#include "field_internal.h"

void *vf__field_alloc(size_t bytes)
{
    /* Big arrays are read at random by the ray marcher: 2 MiB alignment lets the kernel back
     * them with huge pages, which cuts TLB misses. */
    size_t align = bytes >= (4u << 20) ? (2u << 20) : 64;
    size_t rounded = (bytes + align - 1) / align * align;
    void *p = NULL;
    if (rounded == 0 || posix_memalign(&p, align, rounded) != 0)
        return NULL;
#ifdef MADV_HUGEPAGE
    if (align > 64)
        madvise(p, rounded, MADV_HUGEPAGE);
#endif
    memset(p, 0, rounded);
    return p;
}

static size_t bit_words(size_t bits)
{
    return (bits + 63) / 64;
}

vf_status vf__field_grid_alloc(field_grid *g, const int dim[3], const float lo[3], float voxel)
{
    memset(g, 0, sizeof *g);
    for (int a = 0; a < 3; a++) {
        if (dim[a] < 2 || dim[a] > 4096)
            return vf_fail(VF_EINPUT, "grid size %dx%dx%d is out of range", dim[0], dim[1], dim[2]);
        g->dim[a] = dim[a];
        g->lo[a] = lo[a];
        g->hi[a] = lo[a] + (float)(dim[a] - 1) * voxel;
        g->cells[a] = dim[a] - 1;
    }
    g->voxel = voxel;
    g->points = (size_t)dim[0] * dim[1] * dim[2];
    size_t cells = (size_t)g->cells[0] * g->cells[1] * g->cells[2];
    g->values = vf__field_alloc(g->points * FIELD_CH * sizeof(float));
    g->cell_bits = vf__field_alloc(bit_words(cells) * sizeof(uint64_t));
    g->empty_radius = vf__field_alloc(cells);
    if (!g->values || !g->cell_bits || !g->empty_radius) {
        vf__field_grid_free(g);
        return vf_fail(VF_EINTERNAL, "out of memory for a %dx%dx%d grid", dim[0], dim[1], dim[2]);
    }
    vf__field_grid_fill_occupancy(g);
    return VF_OK;
}

void vf__field_grid_free(field_grid *g)
{
    free(g->values);
    free(g->half);
    free(g->cell_bits);
    free(g->empty_radius);
    memset(g, 0, sizeof *g);
}

void vf__field_grid_fill_occupancy(field_grid *g)
{
    size_t cells = (size_t)g->cells[0] * g->cells[1] * g->cells[2];
    memset(g->cell_bits, 0xff, bit_words(cells) * sizeof(uint64_t));
    memset(g->empty_radius, 0, cells);
    for (int a = 0; a < 3; a++) {
        g->occ_lo[a] = 0;
        g->occ_hi[a] = g->cells[a];
    }
}

size_t vf__field_grid_occupied_cells(const field_grid *g)
{
    size_t cells = (size_t)g->cells[0] * g->cells[1] * g->cells[2], count = 0;
    for (size_t w = 0; w < cells / 64; w++)
        count += (size_t)__builtin_popcountll(g->cell_bits[w]);
    for (size_t c = cells / 64 * 64; c < cells; c++)
        count += (size_t)field_cell_occupied(g, c);
    return count;
}

/* Trilinear value of all channels of `g` at grid coordinates u (clamped to the grid). */
static void sample_point(const field_grid *g, const float u[3], float out[FIELD_CH])
{
    int c[3];
    float f[3];
    for (int a = 0; a < 3; a++) {
        float x = fminf(fmaxf(u[a], 0.0f), (float)g->cells[a]);
        c[a] = (int)x < g->cells[a] ? (int)x : g->cells[a] - 1;
        f[a] = x - (float)c[a];
    }
    size_t sx = 1, sy = (size_t)g->dim[0], sz = sy * (size_t)g->dim[1];
    const float *base = g->values + ((size_t)c[0] + sy * c[1] + sz * c[2]) * FIELD_CH;
    memset(out, 0, FIELD_CH * sizeof(float));
    for (int corner = 0; corner < 8; corner++) {
        int bx = corner & 1, by = (corner >> 1) & 1, bz = corner >> 2;
        float w = (bx ? f[0] : 1 - f[0]) * (by ? f[1] : 1 - f[1]) * (bz ? f[2] : 1 - f[2]);
        const float *p = base + (sx * bx + sy * by + sz * bz) * FIELD_CH;
        for (int ch = 0; ch < FIELD_CH; ch++)
            out[ch] += w * p[ch];
    }
}

vf_status vf__field_grid_resample(const field_grid *src, float voxel, field_grid *out)
{
    int dim[3];
    for (int a = 0; a < 3; a++)
        dim[a] = (int)ceilf((src->hi[a] - src->lo[a]) / voxel - 1e-3f) + 1;
    vf_status status = vf__field_grid_alloc(out, dim, src->lo, voxel);
    if (status != VF_OK)
        return status;
    float scale = voxel / src->voxel;
#pragma omp parallel for schedule(static)
    for (int z = 0; z < dim[2]; z++)
        for (int y = 0; y < dim[1]; y++)
            for (int x = 0; x < dim[0]; x++) {
                float u[3] = {(float)x * scale, (float)y * scale, (float)z * scale};
                size_t i = (size_t)x + (size_t)dim[0] * ((size_t)y + (size_t)dim[1] * z);
                sample_point(src, u, out->values + i * FIELD_CH);
            }
    return VF_OK;
}

float vf__field_density_threshold(const vf_field *f, float threshold, float step_world)
{
    /* alpha = 1 - exp(-softplus(d + shift) * scale * step) */
    float sigma = -logf(1.0f - threshold) / (f->density_scale * step_world);
    float softplus_inv = sigma > 20.0f ? sigma : logf(expm1f(sigma));
    return softplus_inv - f->density_shift;
}

void vf__field_grid_update_occupancy(field_grid *g, const vf_field *f, float step_world)
{
    float d_min = vf__field_density_threshold(f, f->occupancy_alpha, step_world);
    size_t cells = (size_t)g->cells[0] * g->cells[1] * g->cells[2];
    uint8_t *point_on = malloc(g->points);
    if (!point_on) { /* cannot refine: keep everything occupied, which is always correct */
        vf__field_grid_fill_occupancy(g);
        return;
    }
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < g->points; i++)
        point_on[i] = g->values[i * FIELD_CH + FIELD_CH_DENSITY] >= d_min;

    memset(g->cell_bits, 0, bit_words(cells) * sizeof(uint64_t));
    size_t sy = (size_t)g->dim[0], sz = sy * (size_t)g->dim[1];
    int cx = g->cells[0], cy = g->cells[1], cz = g->cells[2];
    /* Each thread owns whole 64-bit words of cell bits (cells are numbered x fastest), so
     * no two threads write the same word. */
#pragma omp parallel for schedule(static)
    for (size_t w = 0; w < bit_words(cells); w++) {
        uint64_t word = 0;
        for (size_t c = w * 64; c < cells && c < w * 64 + 64; c++) {
            int x = (int)(c % (size_t)cx), y = (int)(c / (size_t)cx % (size_t)cy);
            int z = (int)(c / ((size_t)cx * cy));
            const uint8_t *p = point_on + (size_t)x + sy * y + sz * z;
            if (p[0] | p[1] | p[sy] | p[sy + 1] | p[sz] | p[sz + 1] | p[sz + sy] | p[sz + sy + 1])
                word |= 1ull << (c - w * 64);
        }
        g->cell_bits[w] = word;
    }
    vf__field_grid_update_empty_radius(g, point_on); /* points > cells: room to spare */
    free(point_on);
    for (int a = 0; a < 3; a++) {
        g->occ_lo[a] = g->cells[a];
        g->occ_hi[a] = 0;
    }
    for (int z = 0; z < cz; z++)
        for (int y = 0; y < cy; y++)
            for (int x = 0; x < cx; x++) {
                size_t c = (size_t)x + (size_t)cx * ((size_t)y + (size_t)cy * z);
                if (field_cell_occupied(g, c)) {
                    const int at[3] = {x, y, z};
                    for (int a = 0; a < 3; a++) {
                        g->occ_lo[a] = at[a] < g->occ_lo[a] ? at[a] : g->occ_lo[a];
                        g->occ_hi[a] = at[a] + 1 > g->occ_hi[a] ? at[a] + 1 : g->occ_hi[a];
                    }
                }
            }
}
