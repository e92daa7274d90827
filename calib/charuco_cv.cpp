// ChArUco boards through OpenCV's aruco module (vf/calib.h, calib/calib_cv.h): the
// dictionary names, a printable board, and finding the corners a view shows. Pixel centres
// cross this boundary at +0.5 (vf/camera.h); OpenCV puts them at integers.
#include "vf/calib.h"
#include "calib_cv.h"

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstring>
#include <new>
#include <strings.h>
#include <vector>

namespace {

struct named_dictionary {
    const char *name;
    cv::aruco::PREDEFINED_DICTIONARY_NAME id;
};

const named_dictionary dictionaries[] = {
    {"4x4_50", cv::aruco::DICT_4X4_50},         {"4x4_100", cv::aruco::DICT_4X4_100},
    {"4x4_250", cv::aruco::DICT_4X4_250},       {"4x4_1000", cv::aruco::DICT_4X4_1000},
    {"5x5_50", cv::aruco::DICT_5X5_50},         {"5x5_100", cv::aruco::DICT_5X5_100},
    {"5x5_250", cv::aruco::DICT_5X5_250},       {"5x5_1000", cv::aruco::DICT_5X5_1000},
    {"6x6_50", cv::aruco::DICT_6X6_50},         {"6x6_100", cv::aruco::DICT_6X6_100},
    {"6x6_250", cv::aruco::DICT_6X6_250},       {"6x6_1000", cv::aruco::DICT_6X6_1000},
    {"7x7_50", cv::aruco::DICT_7X7_50},         {"7x7_100", cv::aruco::DICT_7X7_100},
    {"7x7_250", cv::aruco::DICT_7X7_250},       {"7x7_1000", cv::aruco::DICT_7X7_1000},
    {"aruco_original", cv::aruco::DICT_ARUCO_ORIGINAL},
};

// OpenCV's board for ours: (cols + 1) x (rows + 1) squares. Its chessboard corners are
// numbered row by row like our uv, so corner id i is our corner i.
cv::Ptr<cv::aruco::CharucoBoard> make_board(const vf_calib_board *board)
{
    cv::Ptr<cv::aruco::Dictionary> dict = cv::aruco::getPredefinedDictionary(
        static_cast<cv::aruco::PREDEFINED_DICTIONARY_NAME>(board->dictionary));
    return cv::aruco::CharucoBoard::create(board->cols + 1, board->rows + 1,
                                           (float)board->square, (float)board->marker, dict);
}

// A board with more markers than its dictionary has codes cannot be made.
vf_status check_size(const vf_calib_board *board)
{
    int markers = (board->cols + 1) * (board->rows + 1) / 2;
    int codes = cv::aruco::getPredefinedDictionary(
                    static_cast<cv::aruco::PREDEFINED_DICTIONARY_NAME>(board->dictionary))
                    ->bytesList.rows;
    if (markers > codes)
        return vf_fail(VF_EINPUT, "a %dx%d ChArUco board needs %d markers but its dictionary "
                                  "has %d: choose a larger one with --dict",
                       board->cols, board->rows, markers, codes);
    if (!(board->marker > 0 && board->marker < board->square))
        return vf_fail(VF_EINPUT, "the ChArUco marker must be smaller than the square");
    return VF_OK;
}

// Where the four outer corners are, from a homography fitted to the visible ones (square
// units on the board). False when the visible corners do not pin one down.
bool outer_quad(const vf_calib_board *board, const std::vector<cv::Point2f> &corners,
                const std::vector<int> &ids, double quad[8])
{
    std::vector<cv::Point2f> on_board;
    for (int id : ids)
        on_board.emplace_back((float)(id % board->cols), (float)(id / board->cols));
    cv::Mat H = cv::findHomography(on_board, corners, 0);
    if (H.empty())
        return false;
    std::vector<cv::Point2f> outer = {{0.0f, 0.0f},
                                      {(float)(board->cols - 1), 0.0f},
                                      {(float)(board->cols - 1), (float)(board->rows - 1)},
                                      {0.0f, (float)(board->rows - 1)}},
                             seen;
    cv::perspectiveTransform(outer, seen, H);
    for (int k = 0; k < 4; k++) {
        quad[2 * k] = seen[k].x + 0.5;
        quad[2 * k + 1] = seen[k].y + 0.5;
    }
    return true;
}

} // namespace

extern "C" vf_status vf_charuco_dictionary(const char *name, int *dictionary)
{
    for (const named_dictionary &d : dictionaries)
        if (!strcasecmp(name, d.name)) {
            *dictionary = d.id;
            return VF_OK;
        }
    return vf_fail(VF_EINPUT, "unknown ArUco dictionary '%s': give one of 4x4_50 ... 7x7_1000 "
                              "(sizes 50, 100, 250, 1000) or aruco_original",
                   name);
}

extern "C" vf_status vf_cv_charuco_image(const vf_calib_board *board, int square_px,
                                         vf_rgb8 *out)
{
    vf_status status = check_size(board);
    if (status != VF_OK)
        return status;
    int width = (board->cols + 3) * square_px, height = (board->rows + 3) * square_px;
    try {
        cv::Mat gray, rgb;
        make_board(board)->draw(cv::Size(width, height), gray, square_px, 1);
        cv::cvtColor(gray, rgb, cv::COLOR_GRAY2RGB);
        if ((status = vf_rgb8_resize_buffer(out, width, height)) == VF_OK)
            rgb.copyTo(cv::Mat(height, width, CV_8UC3, out->data));
        return status;
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINTERNAL, "drawing the ChArUco board failed: %s", e.err.c_str());
    } catch (const std::bad_alloc &) {
        return vf_fail(VF_EINTERNAL, "out of memory drawing the ChArUco board");
    }
}

extern "C" vf_status vf_cv_find_charuco(const vf_rgb8 *frame, const vf_calib_board *board,
                                        double *uv, double quad[8], int *found)
{
    *found = 0;
    vf_status status = check_size(board);
    if (status != VF_OK)
        return status;
    try {
        cv::Mat gray;
        cv::cvtColor(cv::Mat(frame->height, frame->width, CV_8UC3, frame->data), gray,
                     cv::COLOR_RGB2GRAY);
        cv::Ptr<cv::aruco::CharucoBoard> charuco = make_board(board);
        std::vector<std::vector<cv::Point2f>> markers, rejected;
        std::vector<int> marker_ids;
        cv::Ptr<cv::aruco::DetectorParameters> params = cv::aruco::DetectorParameters::create();
        cv::aruco::detectMarkers(gray, charuco->dictionary, markers, marker_ids, params, rejected);
        // the board's layout finds markers the first pass missed
        cv::aruco::refineDetectedMarkers(gray, charuco, markers, marker_ids, rejected);
        if (marker_ids.size() < 2)
            return VF_OK;
        std::vector<cv::Point2f> corners;
        std::vector<int> ids;
        cv::aruco::interpolateCornersCharuco(markers, marker_ids, gray, charuco, corners, ids);
        if ((int)ids.size() < VF_CHARUCO_MIN_CORNERS || !outer_quad(board, corners, ids, quad))
            return VF_OK;
        int n = board->cols * board->rows; /* inner corners, as vf_calib_board_corners */
        for (int i = 0; i < 2 * n; i++)
            uv[i] = NAN;
        for (size_t k = 0; k < ids.size(); k++) {
            uv[2 * ids[k]] = corners[k].x + 0.5;
            uv[2 * ids[k] + 1] = corners[k].y + 0.5;
        }
        *found = 1;
        return VF_OK;
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINTERNAL, "ChArUco search failed: %s", e.err.c_str());
    } catch (const std::bad_alloc &) {
        return vf_fail(VF_EINTERNAL, "out of memory searching for the ChArUco board");
    }
}
