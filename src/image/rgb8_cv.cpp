// The OpenCV side of vf/rgb8.h: decode, encode, read, write and shrink 8-bit RGB frames.
// OpenCV works in BGR; every frame crosses this boundary as RGB. Every cv::Exception becomes a
// vf_status with a one-line message.
#include "vf/rgb8.h"
#include "rgb8_cv.h"

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/photo.hpp>

#include <strings.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>
#include <vector>

#include "vf/fsutil.h"

namespace {

// OpenCV logs its own warning for a file it cannot read; we report it once ourselves.
struct QuietLog {
    cv::utils::logging::LogLevel saved =
        cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
    ~QuietLog() { cv::utils::logging::setLogLevel(saved); }
};

// A Mat header over a frame's pixels (no copy).
cv::Mat wrap(const vf_rgb8 *img)
{
    return cv::Mat(img->height, img->width, CV_8UC3, img->data);
}

// Copy a BGR Mat into out as RGB (out's pixels reused when the size matches).
vf_status store_bgr(const cv::Mat &bgr, vf_rgb8 *out)
{
    vf_status status = vf_rgb8_resize_buffer(out, bgr.cols, bgr.rows);
    if (status != VF_OK)
        return status;
    cv::Mat dst = wrap(out);
    cv::cvtColor(bgr, dst, cv::COLOR_BGR2RGB);
    return VF_OK;
}

// Any 8/16-bit or float image with 1, 3 or 4 channels (BGR order) to 8-bit BGR; alpha is
// composited onto white, the background the photo-room style captures are shot against.
cv::Mat to_bgr8(const cv::Mat &src)
{
    cv::Mat img = src;
    if (img.depth() == CV_16U)
        img.convertTo(img, CV_8U, 1.0 / 257.0);
    else if (img.depth() == CV_32F || img.depth() == CV_64F)
        img.convertTo(img, CV_8U, 255.0);
    else if (img.depth() != CV_8U)
        img.convertTo(img, CV_8U);
    if (img.channels() == 1) {
        cv::Mat bgr;
        cv::cvtColor(img, bgr, cv::COLOR_GRAY2BGR);
        return bgr;
    }
    if (img.channels() != 4)
        return img;
    cv::Mat bgr(img.rows, img.cols, CV_8UC3);
    for (int y = 0; y < img.rows; y++) {
        const unsigned char *s = img.ptr<unsigned char>(y);
        unsigned char *d = bgr.ptr<unsigned char>(y);
        for (int x = 0; x < img.cols; x++, s += 4, d += 3) {
            int a = s[3];
            for (int c = 0; c < 3; c++)
                d[c] = (unsigned char)((s[c] * a + 255 * (255 - a) + 127) / 255);
        }
    }
    return bgr;
}

bool is_jpeg_name(const char *path)
{
    const char *dot = std::strrchr(path, '.');
    if (!dot)
        return false;
    std::string ext(dot + 1);
    for (char &c : ext)
        c = (char)std::tolower((unsigned char)c);
    return ext == "jpg" || ext == "jpeg";
}

vf_status encode(const vf_rgb8 *img, const char *ext, const std::vector<int> &params,
                 std::vector<unsigned char> &bytes)
{
    if (!img->data || img->width <= 0 || img->height <= 0)
        return vf_fail(VF_EINPUT, "cannot encode an empty frame");
    try {
        cv::Mat bgr;
        cv::cvtColor(wrap(img), bgr, cv::COLOR_RGB2BGR);
        if (!cv::imencode(ext, bgr, bytes, params))
            return vf_fail(VF_EINTERNAL, "cannot encode a %dx%d frame as %s", img->width,
                           img->height, ext);
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINTERNAL, "cannot encode a frame as %s: %s", ext, e.err.c_str());
    } catch (const std::bad_alloc &) {
        return vf_fail(VF_EINTERNAL, "out of memory encoding a frame");
    }
    return VF_OK;
}

} // namespace

extern "C" vf_status vf_rgb8_decode(const void *bytes, size_t size, vf_rgb8 *out)
{
    QuietLog quiet;
    try {
        cv::Mat buffer(1, (int)size, CV_8U, const_cast<void *>(bytes));
        cv::Mat bgr = cv::imdecode(buffer, cv::IMREAD_COLOR);
        if (bgr.empty())
            return vf_fail(VF_EINPUT, "cannot decode a %zu-byte frame: not a JPEG or PNG", size);
        return store_bgr(bgr, out);
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINPUT, "cannot decode a %zu-byte frame: %s", size, e.err.c_str());
    } catch (const std::bad_alloc &) {
        return vf_fail(VF_EINTERNAL, "out of memory decoding a frame");
    }
}

extern "C" vf_status vf_rgb8_encode_jpeg(const vf_rgb8 *img, int quality, unsigned char **bytes,
                                         size_t *size)
{
    std::vector<unsigned char> buffer;
    vf_status status = encode(img, ".jpg", {cv::IMWRITE_JPEG_QUALITY, quality}, buffer);
    if (status != VF_OK)
        return status;
    *bytes = (unsigned char *)std::malloc(buffer.size());
    if (!*bytes)
        return vf_fail(VF_EINTERNAL, "out of memory encoding a frame");
    std::memcpy(*bytes, buffer.data(), buffer.size());
    *size = buffer.size();
    return VF_OK;
}

extern "C" vf_status vf_cv_read(const char *path, vf_rgb8 *out)
{
    QuietLog quiet;
    try {
        // As stored: IMREAD_UNCHANGED keeps alpha (composited below) and ignores EXIF
        // orientation, which rgb8.c applies by the project's one rule (vf_image_orientation).
        cv::Mat img = cv::imread(path, cv::IMREAD_UNCHANGED);
        if (img.empty())
            return vf_fail(VF_EINPUT, "cannot read %s: not an image OpenCV can decode", path);
        return store_bgr(to_bgr8(img), out);
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINPUT, "cannot read %s: %s", path, e.err.c_str());
    } catch (const std::bad_alloc &) {
        return vf_fail(VF_EINTERNAL, "out of memory reading %s", path);
    }
}

extern "C" vf_status vf_rgb8_save(const char *path, const vf_rgb8 *img)
{
    std::vector<unsigned char> bytes;
    vf_status status;
    if (is_jpeg_name(path))
        status = encode(img, ".jpg", {cv::IMWRITE_JPEG_QUALITY, 95}, bytes);
    else if (std::strlen(path) > 4 && !strcasecmp(path + std::strlen(path) - 4, ".png"))
        status = encode(img, ".png", {}, bytes);
    else
        return vf_fail(VF_EINPUT, "cannot write %s: unknown extension (use .jpg or .png)", path);
    if (status != VF_OK) {
        vf_error_prefix("%s", path);
        return status;
    }
    return vf_write_file_atomic(path, bytes.data(), bytes.size());
}

extern "C" vf_status vf_rgb8_fit(const vf_rgb8 *src, int max_side, vf_rgb8 *out)
{
    if (!src->data || max_side <= 0)
        return vf_fail(VF_EINPUT, "cannot fit a %dx%d frame into %d pixels", src->width,
                       src->height, max_side);
    int longer = src->width > src->height ? src->width : src->height;
    double scale = longer > max_side ? (double)max_side / longer : 1.0;
    int width = std::max(1, (int)std::lround(src->width * scale));
    int height = std::max(1, (int)std::lround(src->height * scale));
    vf_rgb8 img = {0, 0, NULL};
    vf_status status = vf_rgb8_resize_buffer(&img, width, height);
    if (status != VF_OK)
        return status;
    try {
        cv::Mat dst = wrap(&img);
        if (scale == 1.0)
            wrap(src).copyTo(dst);
        else
            cv::resize(wrap(src), dst, dst.size(), 0, 0, cv::INTER_AREA);
    } catch (const cv::Exception &e) {
        vf_rgb8_free(&img);
        return vf_fail(VF_EINTERNAL, "resizing a frame failed: %s", e.err.c_str());
    }
    *out = img;
    return VF_OK;
}

extern "C" vf_status vf_rgb8_denoise(vf_rgb8 *img, double strength)
{
    if (strength <= 0)
        return VF_OK;
    try {
        cv::Mat pixels = wrap(img), clean;
        cv::fastNlMeansDenoisingColored(pixels, clean, (float)strength, (float)strength, 7, 21);
        clean.copyTo(pixels);
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINTERNAL, "denoising a frame failed: %s", e.err.c_str());
    } catch (const std::bad_alloc &) {
        return vf_fail(VF_EINTERNAL, "out of memory denoising a %dx%d frame", img->width,
                       img->height);
    }
    return VF_OK;
}
