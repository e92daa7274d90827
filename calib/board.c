/* The board: its corner layout, a printable image (ChArUco: drawn by OpenCV), and the set of
 * views it was found in (vf/calib.h). */
#include <stdlib.h>
#include <string.h>

#include "calib_cv.h"
#include "calib_internal.h"

int vf_calib_board_corners(const vf_calib_board *board)
{
    return board->cols * board->rows;
}

double *vf__calib_board_points(const vf_calib_board *board)
{
    int n = vf_calib_board_corners(board);
    double *xy = malloc((size_t)n * 2 * sizeof *xy);
    for (int i = 0; xy && i < n; i++) {
        xy[2 * i] = (i % board->cols) * board->square;
        xy[2 * i + 1] = (i / board->cols) * board->square;
    }
    return xy;
}

vf_status vf_calib_board_image(const vf_calib_board *board, int square_px, vf_rgb8 *out)
{
    if (board->cols < 2 || board->rows < 2 || square_px < 1)
        return vf_fail(VF_EINPUT, "a board needs at least 2 x 2 inner corners");
    if (board->marker > 0)
        return vf_cv_charuco_image(board, square_px, out);
    int squares_x = board->cols + 1, squares_y = board->rows + 1;
    int width = (squares_x + 2) * square_px, height = (squares_y + 2) * square_px;
    vf_status status = vf_rgb8_resize_buffer(out, width, height);
    if (status != VF_OK)
        return status;
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            int sx = x / square_px - 1, sy = y / square_px - 1; /* square, -1 in the margin */
            int inside = sx >= 0 && sy >= 0 && sx < squares_x && sy < squares_y;
            unsigned char value = inside && (sx + sy) % 2 == 0 ? 0 : 255;
            memset(out->data + 3 * ((size_t)y * width + x), value, 3);
        }
    return VF_OK;
}

vf_status vf_calib_views_add(vf_calib_views *set, int width, int height, const char *name,
                             const double *uv, const double quad[8], int corners)
{
    if (set->count == 0 && set->width == 0) {
        set->width = width;
        set->height = height;
    } else if (width != set->width || height != set->height) {
        return vf_fail(VF_EINPUT, "%s is %dx%d but the earlier frames are %dx%d: calibrate "
                                  "frames of one size",
                       name, width, height, set->width, set->height);
    }
    if (set->count == set->capacity) {
        int capacity = set->capacity ? 2 * set->capacity : 64;
        vf_calib_view *grown = realloc(set->views, (size_t)capacity * sizeof *grown);
        if (!grown)
            return vf_fail(VF_EINTERNAL, "out of memory");
        set->views = grown;
        set->capacity = capacity;
    }
    vf_calib_view *view = &set->views[set->count];
    memset(view, 0, sizeof *view);
    view->uv = malloc((size_t)corners * 2 * sizeof *view->uv);
    if (!view->uv)
        return vf_fail(VF_EINTERNAL, "out of memory");
    memcpy(view->uv, uv, (size_t)corners * 2 * sizeof *uv);
    memcpy(view->quad, quad, sizeof view->quad);
    snprintf(view->name, sizeof view->name, "%s", name);
    set->count++;
    return VF_OK;
}

void vf_calib_views_free(vf_calib_views *set)
{
    for (int i = 0; i < set->count; i++)
        free(set->views[i].uv);
    free(set->views);
    memset(set, 0, sizeof *set);
}
