/* vf/calib.h: camera calibration from a checkerboard or ChArUco board, and metric scale for a
 * workspace.
 *
 * Intrinsics: frames that show a planar checkerboard (or ChArUco board) of known square size
 * are searched for its inner corners (OpenCV, calib/calib_cv.cpp and calib/charuco_cv.cpp);
 * well-spread views are kept; OpenCV's calibrateCamera gives the first estimate of the OPENCV
 * lens (fx, fy, cx, cy, k1, k2, p1, p2, as COLMAP and vf/camera.h use it); views that
 * reproject badly are dropped; Ceres then refines lens and board poses together under a robust
 * (Huber) loss (src/ceres/calib_refine.cpp).
 * Pixel coordinates follow vf/camera.h: the image corner is (0, 0), pixel centres at +0.5.
 *
 * Scale: a workspace's scene units (object frame of WS/poses/transforms.json) are tied to
 * metres by triangulating points of known separation over posed frames: the four corners of
 * a printed ArUco marker (the original ArUco dictionary, 1024 ids, OpenCV's
 * DICT_ARUCO_ORIGINAL) or two points a person picked in two or more frames each. The factor is
 * kept in WS/calib/scale.json; vf_workspace_metres_per_unit() reads it for other commands.
 *
 * Memory: structs filled here own their arrays and are released with their _free function;
 * images are the caller's. */
#ifndef VF_CALIB_H
#define VF_CALIB_H

#include <jansson.h>

#include "vf/camera.h"
#include "vf/error.h"
#include "vf/rgb8.h"
#include "vf/v4l2.h"
#include "vf/workspace.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- the board: a checkerboard, or a ChArUco board ----
 *
 * A ChArUco board is a checkerboard with an ArUco marker in each white square (OpenCV's
 * aruco module). The markers name the corners around them, so a view that shows only part of
 * the board still counts: corners it does not show are NaN in that view's uv. */

typedef struct vf_calib_board {
    int cols, rows; /* inner corners (where four squares meet): a 10 x 7 squares board is 9 x 6 */
    double square;  /* side of one square, in the unit the poses should have (metres) */
    double marker;  /* ChArUco: side of a marker, same unit; 0 for a plain checkerboard */
    int dictionary; /* ChArUco: the markers' dictionary (vf_charuco_dictionary) */
} vf_calib_board;

#define VF_CHARUCO_MARKER_RATIO 0.75 /* marker side / square side on boards we print */

/* Inner-corner count of a board: cols * rows. */
int vf_calib_board_corners(const vf_calib_board *board);

/* The dictionary called name ("4x4_50", "5x5_100", "6x6_250", "aruco_original", ... as
 * OpenCV's DICT_* names without the prefix, any case) for vf_calib_board.dictionary. */
vf_status vf_charuco_dictionary(const char *name, int *dictionary);

/* A printable board: (cols + 1) x (rows + 1) squares of square_px pixels with a white margin
 * of one square all round; the top-left square is black. A ChArUco board (marker > 0) gets
 * markers of VF_CHARUCO_MARKER_RATIO times the square in its white squares. */
vf_status vf_calib_board_image(const vf_calib_board *board, int square_px, vf_rgb8 *out);

/* Find the board's inner corners in a frame; uv gets 2 * cols * rows doubles, row by row.
 * *found is 1 when the view is usable: a checkerboard with every corner seen, or a ChArUco
 * board with at least VF_CHARUCO_MIN_CORNERS corners (the others NaN). quad gets the board's
 * four outer inner corners (first and last of the top row, last and first of the bottom row),
 * where they are, or would be when hidden. */
#define VF_CHARUCO_MIN_CORNERS 12
vf_status vf_calib_find_board(const vf_rgb8 *frame, const vf_calib_board *board, double *uv,
                              double quad[8], int *found);

/* ---- intrinsics ---- */

/* One frame in which the board was found. */
typedef struct vf_calib_view {
    char name[128]; /* where it came from: a file name or "frame 123" */
    double *uv;     /* 2 * corners pixel positions (owned), NaN where a corner was not seen */
    double quad[8]; /* the board's outer corners, as vf_calib_find_board gives them */
    double rms;     /* reprojection error of this view after calibration, pixels (0 unused) */
    int state;      /* VF_VIEW_* below */
} vf_calib_view;

enum {
    VF_VIEW_SPARE = 0,   /* found, but too close to views already kept */
    VF_VIEW_USED = 1,    /* in the final calibration */
    VF_VIEW_OUTLIER = 2, /* dropped: reprojected much worse than the others */
};

typedef struct vf_calib_views {
    int width, height; /* frame size (every frame must have it) */
    int count, capacity;
    vf_calib_view *views;
    int frames_seen;   /* frames searched, with or without a board */
} vf_calib_views;

/* Add a found board (uv and quad are copied). The first call fixes the frame size. */
vf_status vf_calib_views_add(vf_calib_views *set, int width, int height, const char *name,
                             const double *uv, const double quad[8], int corners);
void vf_calib_views_free(vf_calib_views *set);

/* Search frames for the board and add every view it is found in. A folder: its .jpg, .jpeg
 * and .png files in name order (searched in parallel). A video: at most max_frames frames,
 * spread evenly over it. A V4L2 webcam: every frame it delivers for `seconds` (ops NULL: the
 * real device). Progress goes to stderr. */
vf_status vf_calib_collect_folder(const char *folder, const vf_calib_board *board,
                                  vf_calib_views *out);
vf_status vf_calib_collect_video(const char *path, const vf_calib_board *board, int max_frames,
                                 vf_calib_views *out);
vf_status vf_calib_collect_camera(const char *device, const vf_v4l2_ops *ops,
                                  const vf_calib_board *board, double seconds,
                                  vf_calib_views *out);

typedef struct vf_calib_options {
    int max_views;         /* well-spread views to calibrate with (default 40) */
    int min_views;         /* fewer found boards than this is an input error (default 6) */
    double outlier_factor; /* a view is an outlier above this times the median view error,
                              and above outlier_floor pixels (defaults 3 and 0.5) */
    double outlier_floor;
    double huber_px;       /* robust loss scale of the Ceres refinement (default 1 pixel) */
} vf_calib_options;

void vf_calib_defaults(vf_calib_options *opt);

typedef struct vf_calib_result {
    vf_camera camera;   /* the calibrated lens, for width x height frames */
    double rms;         /* RMS reprojection error over the used views' corners, pixels */
    double rms_opencv;  /* the same after OpenCV alone (before outlier removal and Ceres) */
    int used, outliers; /* views calibrated with / dropped */
    double seconds_opencv, seconds_ceres;
} vf_calib_result;

/* Calibrate from the found views: chooses views (marks them VF_VIEW_USED), drops outliers
 * (VF_VIEW_OUTLIER), fills each used view's rms and the result. VF_EINPUT when fewer than
 * opt->min_views boards were found, naming the board and what to try. */
vf_status vf_calib_solve(vf_calib_views *set, const vf_calib_board *board,
                         const vf_calib_options *opt, vf_calib_result *out);

/* The camera file `poses --camera` reads: fl_x, fl_y, cx, cy, w, h, k1, k2, p1, p2, plus rms,
 * views, the board and every view's error. Written atomically. */
vf_status vf_calib_save_camera(const char *path, const vf_calib_result *res,
                               const vf_calib_views *set, const vf_calib_board *board);

/* Read a camera file (the one module that does): fl_x (or fx), fl_y (or fy), cx, cy, w (or
 * width), h (or height) in pixels, and k1, k2, p1, p2 when present (else 0). VF_EINPUT naming
 * the file and the key when a value is missing or out of range (focal lengths and the
 * principal point in (0, 1e6), w and h whole numbers 1 to 100000, distortion |k| <= 100). */
vf_status vf_calib_load_camera(const char *path, vf_camera *cam);

/* ---- geometry shared by the calibration and its tests ---- */

/* Render a textured plane through a lens: the texture lies on the plane z = 0 of its own
 * frame, texel (i, j) covering [i, i+1) x [j, j+1) * texel_size; rot/t map plane points into
 * the camera (OpenCV axes: x_cam = rot * x_plane + t). Pixels that miss the texture get
 * `background`. supersample (1..4) renders larger and shrinks, against aliasing. */
vf_status vf_calib_render_plane(const vf_camera *cam, const double rot[9], const double t[3],
                                const vf_rgb8 *texture, double texel_size,
                                unsigned char background, int supersample, vf_rgb8 *out);

/* The point nearest (least squares) to n >= 2 rays origin[i] + s dir[i] (dir unit length).
 * VF_EINPUT when the rays are (nearly) parallel, so depth is not determined. */
vf_status vf_triangulate_rays(const double *origin, const double *dir, int n, double out[3]);

/* ---- ArUco markers (original dictionary) ---- */

#define VF_ARUCO_IDS 1024

/* A printable marker: 7 x 7 cells (black border, 5 x 5 code) of cell_px pixels, inside a white
 * margin of one cell. The marker's side (what --size measures) is the black square, 7 cells. */
vf_status vf_aruco_image(int id, int cell_px, vf_rgb8 *out);

/* The id coded by a 5 x 5 bit grid (row by row, 1 = white) read in the marker's own
 * orientation, or -1 when it is not a valid code. */
int vf_aruco_decode(const unsigned char bits[25]);

typedef struct vf_marker {
    int id;
    double corners[8]; /* (u, v) of the marker's top-left, top-right, bottom-right and
                          bottom-left corners as printed, subpixel */
} vf_marker;

/* Find the ArUco markers in a frame (at most max; *count gets how many were stored). */
vf_status vf_aruco_detect(const vf_rgb8 *frame, vf_marker *markers, int max, int *count);

/* ---- metric scale of a workspace ---- */

/* Where one point was seen: a frame (its image file name, with or without the extension)
 * and the pixel, in that image as stored. */
typedef struct vf_pick {
    char frame[128];
    double u, v;
} vf_pick;

/* Parse "NAME:U,V;NAME:U,V[;...]" (at least two picks) into picks; *count gets how many. */
vf_status vf_parse_picks(const char *text, vf_pick *picks, int max, int *count);

/* Scale from a marker of side size_m metres seen in the posed frames of the workspace
 * (WS/poses/transforms.json, else a posed import's WS/ingest/transforms.json). *details
 * (a new JSON object) says which frames saw it, the triangulated corners and side lengths. */
vf_status vf_scale_from_marker(const vf_workspace *ws, int id, double size_m,
                               double *metres_per_unit, json_t **details);

/* Scale from two points picked in the frames (each in at least two) and their distance. */
vf_status vf_scale_from_picks(const vf_workspace *ws, const vf_pick *p1, int n1,
                              const vf_pick *p2, int n2, double distance_m,
                              double *metres_per_unit, json_t **details);

/* The calib stage's scale: a marker (id >= 0, size_m) or two points (p1 and p2 non-NULL:
 * the picks' text as vf_parse_picks reads it, distance_m apart). */
typedef struct vf_scale_request {
    int marker;            /* ArUco id, or -1 */
    double size_m;         /* the marker's black square, metres */
    const char *p1, *p2;   /* or two picked points... */
    double distance_m;     /* ...this far apart */
} vf_scale_request;

/* Measure the scale and keep it as the workspace's calib stage (WS/calib/scale.json:
 * metres_per_unit, units_per_metre, method, details); *result (a new reference) is that
 * document. A failed measurement leaves the workspace as it was. */
vf_status vf_calib_scale_run(vf_workspace *ws, const vf_scale_request *r, json_t **result);

/* Whether the workspace has a metric scale (WS/calib/scale.json); *metres_per_unit gets it. */
int vf_workspace_metres_per_unit(const vf_workspace *ws, double *metres_per_unit);

#ifdef __cplusplus
}
#endif
#endif
