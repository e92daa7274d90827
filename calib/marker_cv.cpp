// Finding ArUco markers (vf/calib.h) with OpenCV's image processing: dark convex quads in an
// adaptively thresholded frame, corners refined to subpixel, the quad rectified and read as a
// 7 x 7 grid (black border, 5 x 5 code decoded by calib/aruco_code.c in each orientation).
// Debian's OpenCV 4.6 has no ArUco in its main modules, so the detector is ours.
#include "vf/calib.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <new>
#include <vector>

namespace {

const int CELL_PX = 8;          // rectified size of one grid cell
const int GRID = 7;             // cells per side: border + 5 code + border
const int MAX_BORDER_ERRORS = 2; // of the 24 border cells, how many may read white
const double MIN_SIDE_PX = 12;  // smaller quads cannot be read

struct Candidate {
    int id;
    std::vector<cv::Point2f> corners; // clockwise on screen, corner 0 the marker's top-left
    double area;
};

cv::Mat wrap(const vf_rgb8 *img)
{
    return cv::Mat(img->height, img->width, CV_8UC3, img->data);
}

// Four-corner convex contours of dark blobs, ordered clockwise on screen.
void find_quads(const cv::Mat &gray, int window, std::vector<std::vector<cv::Point2f>> &quads)
{
    cv::Mat binary;
    cv::adaptiveThreshold(gray, binary, 255, cv::ADAPTIVE_THRESH_MEAN_C, cv::THRESH_BINARY_INV,
                          window, 7);
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(binary, contours, cv::RETR_LIST, cv::CHAIN_APPROX_NONE);
    for (const auto &contour : contours) {
        if (contour.size() < 4 * MIN_SIDE_PX)
            continue;
        std::vector<cv::Point> poly;
        cv::approxPolyDP(contour, poly, 0.04 * contour.size(), true);
        if (poly.size() != 4 || !cv::isContourConvex(poly))
            continue;
        bool ok = true;
        for (int k = 0; k < 4 && ok; k++) {
            const cv::Point &p = poly[k];
            ok = cv::norm(p - poly[(k + 1) % 4]) >= MIN_SIDE_PX && p.x > 1 && p.y > 1 &&
                 p.x < gray.cols - 2 && p.y < gray.rows - 2;
        }
        if (!ok)
            continue;
        std::vector<cv::Point2f> quad(poly.begin(), poly.end());
        cv::Point2f a = quad[1] - quad[0], b = quad[2] - quad[0];
        if (a.x * b.y - a.y * b.x < 0) // counter-clockwise on screen (y down): flip
            std::swap(quad[1], quad[3]);
        quads.push_back(quad);
    }
}

// Read the rectified quad as a grid of cells, 1 = white. Returns false when the border is not
// black.
bool read_grid(const cv::Mat &gray, const std::vector<cv::Point2f> &quad, unsigned char code[25])
{
    const float side = (float)(GRID * CELL_PX);
    const cv::Point2f square[4] = {{0, 0}, {side, 0}, {side, side}, {0, side}};
    cv::Mat H = cv::getPerspectiveTransform(quad.data(), square), rectified, binary;
    cv::warpPerspective(gray, rectified, H, cv::Size(GRID * CELL_PX, GRID * CELL_PX),
                        cv::INTER_LINEAR);
    cv::threshold(rectified, binary, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
    int border_errors = 0;
    const int margin = CELL_PX / 4; // read each cell's middle, away from blurred edges
    for (int cy = 0; cy < GRID; cy++)
        for (int cx = 0; cx < GRID; cx++) {
            cv::Rect cell(cx * CELL_PX + margin, cy * CELL_PX + margin, CELL_PX - 2 * margin,
                          CELL_PX - 2 * margin);
            bool white = cv::countNonZero(binary(cell)) * 2 > cell.area();
            bool border = cx == 0 || cy == 0 || cx == GRID - 1 || cy == GRID - 1;
            if (border)
                border_errors += white;
            else
                code[5 * (cy - 1) + (cx - 1)] = white;
        }
    return border_errors <= MAX_BORDER_ERRORS;
}

// Decode in each of the four orientations; on success the corners are reordered so corner 0
// is the marker's own top-left.
bool decode(const unsigned char grid[25], std::vector<cv::Point2f> &quad, int *id)
{
    unsigned char bits[25], turned[25];
    std::copy(grid, grid + 25, bits);
    for (int turn = 0; turn < 4; turn++) {
        int found = vf_aruco_decode(bits);
        if (found >= 0) {
            std::rotate(quad.begin(), quad.begin() + turn, quad.end());
            *id = found;
            return true;
        }
        // Corners shifted by one (new top-left = old top-right): new(y, x) = old(x, 4 - y).
        for (int y = 0; y < 5; y++)
            for (int x = 0; x < 5; x++)
                turned[5 * y + x] = bits[5 * x + (4 - y)];
        std::copy(turned, turned + 25, bits);
    }
    return false;
}

double quad_area(const std::vector<cv::Point2f> &q)
{
    return std::fabs(cv::contourArea(q));
}

} // namespace

extern "C" vf_status vf_aruco_detect(const vf_rgb8 *frame, vf_marker *markers, int max, int *count)
{
    *count = 0;
    try {
        cv::Mat gray;
        cv::cvtColor(wrap(frame), gray, cv::COLOR_RGB2GRAY);
        // Threshold windows from fine to coarse: small markers and large, evenly lit ones.
        int shorter = std::min(gray.cols, gray.rows);
        std::vector<std::vector<cv::Point2f>> quads;
        for (int window : {7, 2 * (shorter / 60) + 15, 2 * (shorter / 20) + 15})
            find_quads(gray, window, quads);
        std::vector<Candidate> found;
        for (auto &quad : quads) {
            unsigned char grid[25];
            int id;
            if (!read_grid(gray, quad, grid) || !decode(grid, quad, &id))
                continue;
            // The same marker from another window: keep the larger (outer) outline.
            cv::Point2f centre = (quad[0] + quad[1] + quad[2] + quad[3]) * 0.25f;
            bool merged = false;
            for (Candidate &c : found) {
                cv::Point2f other = (c.corners[0] + c.corners[1] + c.corners[2] + c.corners[3]) *
                                    0.25f;
                if (c.id == id && cv::norm(centre - other) < 0.25 * std::sqrt(c.area)) {
                    if (quad_area(quad) > c.area)
                        c = Candidate{id, quad, quad_area(quad)};
                    merged = true;
                    break;
                }
            }
            if (!merged)
                found.push_back(Candidate{id, quad, quad_area(quad)});
        }
        for (Candidate &c : found) {
            if (*count == max)
                break;
            double side = std::sqrt(c.area);
            int half = (int)std::clamp(side / 14.0, 2.0, 6.0); // within the border's width
            cv::cornerSubPix(gray, c.corners, cv::Size(half, half), cv::Size(-1, -1),
                             cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT,
                                              30, 0.01));
            vf_marker *m = &markers[(*count)++];
            m->id = c.id;
            for (int k = 0; k < 4; k++) {
                m->corners[2 * k] = c.corners[k].x + 0.5;
                m->corners[2 * k + 1] = c.corners[k].y + 0.5;
            }
        }
        return VF_OK;
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINTERNAL, "marker search failed: %s", e.err.c_str());
    } catch (const std::bad_alloc &) {
        return vf_fail(VF_EINTERNAL, "out of memory searching for markers");
    }
}
