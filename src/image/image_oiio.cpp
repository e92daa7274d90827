// The OpenImageIO side of vf/image.h: reading and writing image files as raw float pixels.
// A thin extern "C" leaf: every OIIO failure becomes a vf_status with a one-line message.
#include "image_oiio.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "vf/fsutil.h" /* vf_is_file, vf_is_dir */

using namespace OIIO;

namespace {

// OIIO's messages can span lines; keep the first one for our one-line errors.
std::string first_line(std::string text)
{
    size_t end = text.find('\n');
    if (end != std::string::npos)
        text.resize(end);
    return text.empty() ? "unknown error" : text;
}

// libpng prints its own "libpng error" line to stderr on a cut-off file before OIIO reports
// it, so walk the chunk list first: every chunk must fit in the file and IEND must be there.
bool png_is_complete(const char *path)
{
    FILE *f = std::fopen(path, "rb");
    if (!f)
        return false;
    unsigned char head[8];
    bool ok = std::fread(head, 1, 8, f) == 8;
    while (ok) {
        if (std::fread(head, 1, 8, f) != 8) {
            ok = false;
            break;
        }
        uint32_t length = (uint32_t)head[0] << 24 | head[1] << 16 | head[2] << 8 | head[3];
        if (std::memcmp(head + 4, "IEND", 4) == 0)
            break;
        // skip the data and the CRC, then make sure they were really there
        if (std::fseek(f, (long)length + 4 - 1, SEEK_CUR) != 0 || std::fgetc(f) == EOF)
            ok = false;
    }
    std::fclose(f);
    return ok;
}

bool has_png_signature(const char *path)
{
    static const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    unsigned char head[8];
    FILE *f = std::fopen(path, "rb");
    bool ok = f && std::fread(head, 1, 8, f) == 8 && std::memcmp(head, signature, 8) == 0;
    if (f)
        std::fclose(f);
    return ok;
}

// Open for reading with straight alpha (OIIO premultiplies PNG alpha by default).
vf_status open_input(const char *path, std::unique_ptr<ImageInput> &in)
{
    if (!vf_is_file(path))
        return vf_fail(VF_EINPUT, "cannot read %s: %s", path,
                       vf_is_dir(path) ? "it is a folder" : "file does not exist");
    if (has_png_signature(path) && !png_is_complete(path))
        return vf_fail(VF_EINPUT, "cannot read %s: truncated PNG file", path);
    ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    in = ImageInput::open(path, &config);
    if (!in) {
        // Opening fails when no reader recognises the header; OIIO's reason can help too.
        std::string why = OIIO::geterror();
        if (why.find("format reader") != std::string::npos || why.empty())
            return vf_fail(VF_EINPUT, "cannot read %s: not an image file", path);
        return vf_fail(VF_EINPUT, "cannot read %s: not an image file (%s)", path,
                       first_line(why).c_str());
    }
    const ImageSpec &spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth > 1)
        return vf_fail(VF_EINPUT, "cannot read %s: unsupported layout (%dx%dx%d, %d channels)",
                       path, spec.width, spec.height, spec.depth, spec.nchannels);
    return VF_OK;
}

// The OIIO format name and pixel type for a file name's extension, or nullptr.
const char *format_for(const char *path, TypeDesc *type)
{
    const char *dot = std::strrchr(path, '.');
    const char *slash = std::strrchr(path, '/');
    if (!dot || (slash && dot < slash))
        return nullptr;
    std::string ext(dot + 1);
    for (char &c : ext)
        c = (char)std::tolower((unsigned char)c);
    *type = TypeDesc::UINT8;
    if (ext == "png")
        return "png";
    if (ext == "jpg" || ext == "jpeg")
        return "jpeg";
    *type = TypeDesc::FLOAT;
    if (ext == "exr")
        return "openexr";
    return nullptr;
}

// Encode the pixels into memory in the given format.
vf_status encode(const char *path, const char *format, TypeDesc type, const float *pixels,
                 int width, int height, int stored_channels, std::vector<unsigned char> &bytes)
{
    Filesystem::IOVecOutput proxy(bytes);
    std::unique_ptr<ImageOutput> out = ImageOutput::create(format, &proxy);
    if (!out)
        return vf_fail(VF_EINTERNAL, "cannot write %s: no %s writer (%s)", path, format,
                       first_line(OIIO::geterror()).c_str());
    // JPEG holds no alpha: write only the colour channels (grey or RGB).
    int channels = stored_channels;
    if (std::strcmp(format, "jpeg") == 0 && (channels == 2 || channels >= 4))
        channels = channels == 2 ? 1 : 3;
    ImageSpec spec(width, height, channels, type);
    if (std::strcmp(format, "png") == 0) // else OIIO un-premultiplies our straight alpha
        spec.attribute("oiio:UnassociatedAlpha", 1);
    if (std::strcmp(format, "jpeg") == 0)
        spec.attribute("CompressionQuality", 95);
    stride_t xstride = (stride_t)(stored_channels * sizeof(float));
    bool ok = out->open("memory", spec) &&
              out->write_image(TypeDesc::FLOAT, pixels, xstride) && out->close();
    if (!ok)
        return vf_fail(VF_EINTERNAL, "cannot write %s: %s", path,
                       first_line(out->geterror()).c_str());
    return VF_OK;
}

// The EXIF orientation (1..8) to apply: a JPEG's, as OpenCV's imread applies it; 1 otherwise.
int orientation_of(ImageInput &in)
{
    if (std::strcmp(in.format_name(), "jpeg") != 0)
        return 1;
    int o = in.spec().get_int_attribute("Orientation", 1);
    return o >= 1 && o <= 8 ? o : 1;
}

} // namespace

extern "C" vf_status vf_oiio_info(const char *path, int *width, int *height, int *channels,
                                   int *orientation)
{
    std::unique_ptr<ImageInput> in;
    vf_status status = open_input(path, in);
    if (status != VF_OK)
        return status;
    *width = in->spec().width;
    *height = in->spec().height;
    *channels = in->spec().nchannels;
    *orientation = orientation_of(*in);
    return VF_OK;
}

extern "C" vf_status vf_oiio_read(const char *path, float **pixels, int *width, int *height,
                                   int *channels, int *orientation)
{
    std::unique_ptr<ImageInput> in;
    vf_status status = open_input(path, in);
    if (status != VF_OK)
        return status;
    const ImageSpec &spec = in->spec();
    size_t count = (size_t)spec.width * (size_t)spec.height * (size_t)spec.nchannels;
    if (count > SIZE_MAX / sizeof(float) / 2 || (size_t)spec.width > SIZE_MAX / spec.height)
        return vf_fail(VF_EINPUT, "cannot read %s: %dx%d is too large", path, spec.width,
                       spec.height);
    float *data = (float *)std::malloc(count * sizeof(float));
    if (!data)
        return vf_fail(VF_EINTERNAL, "out of memory for a %dx%d image", spec.width, spec.height);
    // A truncated JPEG "succeeds" (grey fill) but leaves an error behind: treat it as failed.
    if (!in->read_image(0, 0, 0, spec.nchannels, TypeDesc::FLOAT, data) || in->has_error()) {
        std::free(data);
        return vf_fail(VF_EINPUT, "cannot read %s: %s", path, first_line(in->geterror()).c_str());
    }
    *pixels = data;
    *width = spec.width;
    *height = spec.height;
    *channels = spec.nchannels;
    *orientation = orientation_of(*in);
    return VF_OK;
}

extern "C" vf_status vf_oiio_encode(const char *path, const float *pixels, int width,
                                     int height, int channels, unsigned char **bytes,
                                     size_t *size)
{
    TypeDesc type;
    const char *format = format_for(path, &type);
    if (!format)
        return vf_fail(VF_EINPUT, "cannot write %s: unknown extension (use .png, .jpg or .exr)",
                       path);
    std::vector<unsigned char> encoded;
    try {
        vf_status status = encode(path, format, type, pixels, width, height, channels, encoded);
        if (status != VF_OK)
            return status;
    } catch (const std::exception &e) {
        return vf_fail(VF_EINTERNAL, "cannot write %s: %s", path, e.what());
    }
    *bytes = (unsigned char *)std::malloc(encoded.size() ? encoded.size() : 1);
    if (!*bytes)
        return vf_fail(VF_EINTERNAL, "out of memory encoding %s", path);
    std::memcpy(*bytes, encoded.data(), encoded.size());
    *size = encoded.size();
    return VF_OK;
}
