// The OpenCV side of vf/video.h: cv::VideoCapture with the FFmpeg backend, rotation applied
// here (not by OpenCV), frames handed out as RGB.
#include "vf/video.h"

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/core/version.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <new>

#include "vf/fsutil.h"

struct vf_video {
    cv::VideoCapture capture;
    int rotation; // clockwise degrees
    cv::Mat bgr, rotated;
};

namespace {

// FFmpeg prints its own complaints ("moov atom not found") on stderr; the caller reports a
// failure once, in one line. OpenCV reads this variable once, when its FFmpeg backend starts.
void quiet_ffmpeg()
{
    setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0); // AV_LOG_QUIET, unless the user set a level
}

// The clockwise rotation that shows the video upright, from OpenCV's orientation property.
// OpenCV 4.6 reports FFmpeg's display-matrix angle as it is (counter-clockwise) but rotates
// as if it were clockwise, so +-90 degree videos come out upside down (opencv/opencv#22088,
// fixed in 4.7). We switch its auto-rotation off and turn the frames ourselves.
int clockwise_rotation(double meta)
{
    int degrees = (((int)std::lround(meta) % 360) + 360) % 360;
#if CV_VERSION_MAJOR == 4 && CV_VERSION_MINOR == 6
    degrees = (360 - degrees) % 360;
#endif
    return degrees;
}

void describe(cv::VideoCapture &capture, int rotation, vf_video_info *info)
{
    info->fps = capture.get(cv::CAP_PROP_FPS);
    if (!std::isfinite(info->fps) || info->fps < 0)
        info->fps = 0;
    double count = capture.get(cv::CAP_PROP_FRAME_COUNT);
    info->frame_count = std::isfinite(count) && count > 0 ? (long)count : 0;
    info->coded_width = (int)capture.get(cv::CAP_PROP_FRAME_WIDTH);
    info->coded_height = (int)capture.get(cv::CAP_PROP_FRAME_HEIGHT);
    bool sideways = rotation == 90 || rotation == 270;
    info->width = sideways ? info->coded_height : info->coded_width;
    info->height = sideways ? info->coded_width : info->coded_height;
    info->rotation = rotation;
    int fourcc = (int)capture.get(cv::CAP_PROP_FOURCC);
    for (int i = 0; i < 4; i++) {
        char c = (char)((fourcc >> (8 * i)) & 0xff);
        info->codec[i] = std::isprint((unsigned char)c) ? c : '?';
    }
    info->codec[fourcc ? 4 : 0] = '\0';
}

} // namespace

extern "C" vf_status vf_video_open(const char *path, vf_video **out, vf_video_info *info)
{
    if (!vf_is_file(path))
        return vf_fail(VF_EINPUT, "%s does not exist", path);
    quiet_ffmpeg();
    cv::utils::logging::LogLevel level =
        cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    vf_status status = VF_OK;
    try {
        std::unique_ptr<vf_video> video(new vf_video);
        if (!video->capture.open(path, cv::CAP_FFMPEG)) {
            status = vf_fail(VF_EINPUT,
                             "%s is not a video FFmpeg can read (empty, damaged or not a video "
                             "file); check that it plays, or give a folder of photos instead",
                             path);
        } else {
            video->capture.set(cv::CAP_PROP_ORIENTATION_AUTO, 0);
            video->rotation = clockwise_rotation(video->capture.get(cv::CAP_PROP_ORIENTATION_META));
            describe(video->capture, video->rotation, info);
            *out = video.release();
        }
    } catch (const cv::Exception &e) {
        status = vf_fail(VF_EINPUT, "cannot read %s as a video: %s", path, e.err.c_str());
    } catch (const std::bad_alloc &) {
        status = vf_fail(VF_EINTERNAL, "out of memory opening %s", path);
    }
    cv::utils::logging::setLogLevel(level);
    return status;
}

extern "C" vf_status vf_video_read(vf_video *video, vf_rgb8 *frame, int *got)
{
    *got = 0;
    try {
        if (!video->capture.read(video->bgr) || video->bgr.empty())
            return VF_OK;
        const cv::Mat *upright = &video->bgr;
        if (video->rotation) {
            int code = video->rotation == 90    ? cv::ROTATE_90_CLOCKWISE
                       : video->rotation == 180 ? cv::ROTATE_180
                                                : cv::ROTATE_90_COUNTERCLOCKWISE;
            cv::rotate(video->bgr, video->rotated, code);
            upright = &video->rotated;
        }
        vf_status status = vf_rgb8_resize_buffer(frame, upright->cols, upright->rows);
        if (status != VF_OK)
            return status;
        cv::Mat rgb(frame->height, frame->width, CV_8UC3, frame->data);
        cv::cvtColor(*upright, rgb, cv::COLOR_BGR2RGB);
        *got = 1;
        return VF_OK;
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINPUT, "decoding a video frame failed: %s", e.err.c_str());
    } catch (const std::bad_alloc &) {
        return vf_fail(VF_EINTERNAL, "out of memory decoding a video frame");
    }
}

extern "C" vf_status vf_video_skip(vf_video *video, int *got)
{
    try {
        *got = video->capture.grab() ? 1 : 0;
        return VF_OK;
    } catch (const cv::Exception &e) {
        *got = 0;
        return vf_fail(VF_EINPUT, "decoding a video frame failed: %s", e.err.c_str());
    }
}

extern "C" void vf_video_close(vf_video *video)
{
    delete video;
}
