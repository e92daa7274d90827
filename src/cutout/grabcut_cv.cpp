// The OpenCV side of vf/cutout.h: GrabCut on labels the caller seeded.
#include "grabcut_cv.h"

#include <opencv2/imgproc.hpp>

#include <cstring>
#include <new>

extern "C" vf_status vf_cv_grabcut(const uint8_t *rgb, int width, int height, uint8_t *labels,
                                 int iterations)
{
    try {
        // GrabCut's colour models do not care about the channel order: RGB is passed as is.
        cv::Mat image(height, width, CV_8UC3, const_cast<uint8_t *>(rgb));
        cv::Mat mask(height, width, CV_8UC1, labels);
        cv::Mat bgd, fgd;
        cv::grabCut(image, mask, cv::Rect(), bgd, fgd, iterations, cv::GC_INIT_WITH_MASK);
        if (mask.data != labels) // grabCut writes into the wrapped buffer; never reallocates it
            std::memcpy(labels, mask.data, (size_t)width * height);
        return VF_OK;
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINTERNAL, "GrabCut failed on a %dx%d image: %s", width, height,
                       e.err.c_str());
    } catch (const std::bad_alloc &) {
        return vf_fail(VF_EINTERNAL, "out of memory in GrabCut");
    }
}
