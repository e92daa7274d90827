// The OpenCV dnn side of vf/classifier.h: load an ONNX network and run batches on the CPU.
// Every cv::Exception becomes a vf_status with a one-line message.
#include "classifier_dnn.h"

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/dnn.hpp>

#include <cstring>
#include <memory>
#include <mutex>
#include <new>
#include <string>

struct vf_dnn {
    cv::dnn::Net net;
};

// OpenCV's importer writes multi-line messages with "> " continuation marks; we print one line.
static std::string one_line(const std::string &text)
{
    std::string out;
    bool space = false;
    for (size_t i = 0; i < text.size(); i++) {
        char c = text[i];
        bool mark = c == '>' && (i == 0 || text[i - 1] == '\n');
        if (c == '\n' || c == '\r' || c == '\t' || c == ' ' || mark) {
            space = !out.empty();
            continue;
        }
        if (space)
            out += ' ';
        out += c;
        space = false;
    }
    return out;
}

// OpenCV logs its own copy of every failure on stderr; we report it once ourselves.
struct quiet_logs {
    cv::utils::logging::LogLevel level =
        cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    ~quiet_logs() { cv::utils::logging::setLogLevel(level); }
};

extern "C" vf_status vf_dnn_load(const char *path, vf_dnn **out)
{
    quiet_logs quiet;
    vf_status status = VF_OK;
    try {
        std::unique_ptr<vf_dnn> dnn(new vf_dnn);
        dnn->net = cv::dnn::readNetFromONNX(path);
        if (dnn->net.empty())
            CV_Error(cv::Error::StsParseError, "it holds no network");
        dnn->net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
        dnn->net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
        // OpenCV's thread count is process-wide: set it once, not on every model open.
        static std::once_flag threads_once;
        std::call_once(threads_once, [] { cv::setNumThreads(cv::getNumberOfCPUs()); });
        *out = dnn.release();
    } catch (const cv::Exception &e) {
        // "Failed to parse ONNX model: PATH": we name the path ourselves.
        std::string why = one_line(e.err), suffix = std::string(": ") + path;
        size_t keep = why.size() - suffix.size();
        if (why.size() > suffix.size() && why.compare(keep, suffix.size(), suffix) == 0)
            why.resize(keep);
        status = vf_fail(VF_EINPUT, "model %s is not an ONNX classifier: %s", path, why.c_str());
    } catch (const std::bad_alloc &) {
        status = vf_fail(VF_EINTERNAL, "out of memory loading model %s", path);
    }
    return status;
}

extern "C" vf_status vf_dnn_forward(vf_dnn *dnn, const float *nchw, int n, int size, float *out,
                                    int classes)
{
    quiet_logs quiet;
    try {
        int shape[4] = {n, 3, size, size};
        // Wraps the caller's buffer without copying; dnn only reads its input.
        cv::Mat blob(4, shape, CV_32F, const_cast<float *>(nchw));
        dnn->net.setInput(blob);
        cv::Mat result = dnn->net.forward();
        if (result.type() != CV_32F || result.total() != (size_t)n * (size_t)classes)
            return vf_fail(VF_EINPUT, "its output has %zu values per image, expected %d",
                           result.total() / (size_t)n, classes);
        if (!result.isContinuous())
            result = result.clone();
        std::memcpy(out, result.ptr<float>(), sizeof(float) * result.total());
        return VF_OK;
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINPUT, "running the model on %d input(s) of %dx%d failed: %s", n, size,
                       size, one_line(e.err).c_str());
    } catch (const std::bad_alloc &) {
        return vf_fail(VF_EINTERNAL, "out of memory running the model");
    }
}

extern "C" void vf_dnn_free(vf_dnn *dnn)
{
    delete dnn;
}

extern "C" const char *vf_dnn_version(void)
{
    return CV_VERSION;
}
