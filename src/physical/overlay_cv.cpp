// The guided-capture window (vf/overlay.h): OpenCV draws the text and highgui (Qt in Debian's
// build) shows it.
#include "vf/overlay.h"

#include <opencv2/highgui.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdlib>
#include <new>
#include <string>
#include <sys/stat.h>

struct vf_overlay {
    std::string title;
    vf_rgb8 canvas;
};

extern "C" int vf_overlay_available(void)
{
    // Only a local display whose socket exists: Qt aborts the process when it cannot
    // connect, and a remote (TCP) display cannot be checked as cheaply.
    const char *display = std::getenv("DISPLAY");
    if (!display || display[0] != ':')
        return 0;
    std::string number(display + 1);
    number = number.substr(0, number.find('.')); // ":0.0" is screen 0 of display 0
    struct stat st;
    return !number.empty() && stat(("/tmp/.X11-unix/X" + number).c_str(), &st) == 0;
}

extern "C" vf_status vf_overlay_draw(const vf_rgb8 *frame, const char *const *lines, int count,
                                     int highlight, vf_rgb8 *out)
{
    vf_status status = vf_rgb8_resize_buffer(out, frame->width, frame->height);
    if (status != VF_OK)
        return status;
    try {
        cv::Mat src(frame->height, frame->width, CV_8UC3, frame->data);
        cv::Mat dst(out->height, out->width, CV_8UC3, out->data);
        src.copyTo(dst);
        // text scaled to the frame: about 60 characters across
        double scale = std::max(0.4, frame->width / 1100.0);
        int thickness = std::max(1, (int)(2 * scale)), line_height = (int)(32 * scale);
        cv::Mat band = dst(cv::Rect(0, 0, dst.cols, std::min(dst.rows, line_height * count + 8)));
        band *= 0.35; // darken, so the text reads on any background
        for (int i = 0; i < count; i++)
            cv::putText(dst, lines[i], cv::Point(8, line_height * (i + 1) - 6),
                        cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(255, 255, 255), thickness,
                        cv::LINE_AA);
        cv::Scalar border = highlight ? cv::Scalar(0, 220, 0) : cv::Scalar(128, 128, 128);
        cv::rectangle(dst, cv::Rect(0, 0, dst.cols, dst.rows), border, std::max(4, thickness * 3));
        return VF_OK;
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINTERNAL, "drawing the overlay failed: %s", e.err.c_str());
    }
}

extern "C" vf_status vf_overlay_open(const char *title, vf_overlay **out)
{
    *out = nullptr;
    if (!vf_overlay_available())
        return vf_fail(VF_EINPUT, "no display to show a window on ($DISPLAY)");
    try {
        vf_overlay *window = new vf_overlay{title, {0, 0, nullptr}};
        cv::namedWindow(window->title, cv::WINDOW_NORMAL);
        *out = window;
        return VF_OK;
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINTERNAL, "cannot open a window: %s", e.err.c_str());
    } catch (const std::bad_alloc &) {
        return vf_fail(VF_EINTERNAL, "out of memory opening a window");
    }
}

extern "C" vf_status vf_overlay_show(vf_overlay *window, const vf_rgb8 *frame,
                                     const char *const *lines, int count, int highlight,
                                     int *quit)
{
    *quit = 0;
    vf_status status = vf_overlay_draw(frame, lines, count, highlight, &window->canvas);
    if (status != VF_OK)
        return status;
    try {
        cv::Mat rgb(window->canvas.height, window->canvas.width, CV_8UC3, window->canvas.data),
            bgr;
        cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
        cv::imshow(window->title, bgr);
        int key = cv::waitKey(1);
        *quit = key == 'q' || key == 27;
        return VF_OK;
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINTERNAL, "showing the window failed: %s", e.err.c_str());
    }
}

extern "C" void vf_overlay_close(vf_overlay *window)
{
    if (!window)
        return;
    try {
        cv::destroyWindow(window->title);
        cv::waitKey(1);
    } catch (const cv::Exception &) {
        // the window is gone already: nothing to release on the OpenCV side
    }
    vf_rgb8_free(&window->canvas);
    delete window;
}
