/* V4L2 capture with mmap streaming; every device call goes through a vf_v4l2_ops table. */
#define _GNU_SOURCE
#include "vf/v4l2.h"

#include <errno.h>
#include <fcntl.h>
#include <linux/videodev2.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#define MAX_BUFFERS 16
#define DEFAULT_BUFFERS 4
#define MAX_BAD_FRAMES 30 /* corrupt frames in a row before giving up */

typedef struct mapped_buffer {
    void *start;
    size_t length;
} mapped_buffer;

struct vf_v4l2 {
    vf_v4l2_ops ops;
    char device[256];
    int fd;
    int wanted_buffers;
    int streaming;
    int mapped_count;
    mapped_buffer buffers[MAX_BUFFERS];
    vf_v4l2_info info;
};

/* ---- the real system calls ---- */

static int sys_open(void *ctx, const char *path, int flags)
{
    (void)ctx;
    return open(path, flags);
}

static int sys_close(void *ctx, int fd)
{
    (void)ctx;
    return close(fd);
}

static int sys_ioctl(void *ctx, int fd, unsigned long request, void *arg)
{
    (void)ctx;
    return ioctl(fd, request, arg);
}

static void *sys_mmap(void *ctx, size_t length, int prot, int flags, int fd, off_t offset)
{
    (void)ctx;
    return mmap(NULL, length, prot, flags, fd, offset);
}

static int sys_munmap(void *ctx, void *addr, size_t length)
{
    (void)ctx;
    return munmap(addr, length);
}

static int sys_poll(void *ctx, struct pollfd *fds, nfds_t count, int timeout_ms)
{
    (void)ctx;
    return poll(fds, count, timeout_ms);
}

const vf_v4l2_ops *vf_v4l2_system_ops(void)
{
    static const vf_v4l2_ops ops = {NULL,     sys_open,   sys_close, sys_ioctl,
                                    sys_mmap, sys_munmap, sys_poll};
    return &ops;
}

/* ---- helpers ---- */

const char *vf_fourcc_text(uint32_t fourcc, char out[5])
{
    for (int i = 0; i < 4; i++) {
        char c = (char)((fourcc >> (8 * i)) & 0xff);
        out[i] = c >= 32 && c < 127 ? c : '?';
    }
    out[4] = '\0';
    return out;
}

/* An ioctl, retried when a signal interrupts it. */
static int xioctl(vf_v4l2 *cam, unsigned long request, void *arg)
{
    int r;
    do
        r = cam->ops.ioctl(cam->ops.ctx, cam->fd, request, arg);
    while (r == -1 && errno == EINTR);
    return r;
}

static vf_status open_error(const char *device, int err)
{
    switch (err) {
    case ENOENT:
    case ENODEV:
    case ENXIO:
        return vf_fail(VF_EINPUT,
                       "camera %s does not exist; list cameras with 'v4l2-ctl --list-devices'",
                       device);
    case EACCES:
    case EPERM:
        return vf_fail(VF_EINPUT,
                       "no permission to open camera %s; add your user to the 'video' group",
                       device);
    case EBUSY:
        return vf_fail(VF_EINPUT, "camera %s is busy; close the program that is using it",
                       device);
    default:
        return vf_fail(VF_EINPUT, "cannot open camera %s: %s", device, strerror(err));
    }
}

/* QUERYCAP: a V4L2 device that can capture single-planar video by streaming. */
static vf_status check_capabilities(vf_v4l2 *cam)
{
    struct v4l2_capability cap;
    memset(&cap, 0, sizeof cap);
    if (xioctl(cam, VIDIOC_QUERYCAP, &cap) == -1)
        return vf_fail(VF_EINPUT, "%s is not a V4L2 camera (%s); give a capture device such as "
                                  "/dev/video0",
                       cam->device, strerror(errno));
    snprintf(cam->info.driver, sizeof cam->info.driver, "%s", (const char *)cap.driver);
    snprintf(cam->info.card, sizeof cam->info.card, "%s", (const char *)cap.card);
    /* device_caps describes this node; capabilities the whole physical device. */
    uint32_t caps = cap.capabilities & V4L2_CAP_DEVICE_CAPS ? cap.device_caps : cap.capabilities;
    if (!(caps & V4L2_CAP_VIDEO_CAPTURE))
        return vf_fail(VF_EINPUT,
                       "%s (%s) is not a video capture device (a webcam's other nodes carry "
                       "metadata); list cameras with 'v4l2-ctl --list-devices'",
                       cam->device, cam->info.card);
    if (!(caps & V4L2_CAP_STREAMING))
        return vf_fail(VF_EINPUT, "%s (%s) cannot stream frames (no V4L2 streaming I/O)",
                       cam->device, cam->info.card);
    return VF_OK;
}

/* ENUM_FMT: pick the wanted pixel format when offered, else the other one we decode. */
static vf_status choose_pixel_format(vf_v4l2 *cam, uint32_t wanted, uint32_t *chosen)
{
    int has_mjpeg = 0, has_yuyv = 0;
    char offered[128] = "";
    struct v4l2_fmtdesc desc;
    for (uint32_t i = 0; i < 64; i++) {
        memset(&desc, 0, sizeof desc);
        desc.index = i;
        desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        if (xioctl(cam, VIDIOC_ENUM_FMT, &desc) == -1)
            break;
        has_mjpeg |= desc.pixelformat == V4L2_PIX_FMT_MJPEG;
        has_yuyv |= desc.pixelformat == V4L2_PIX_FMT_YUYV;
        char text[5];
        size_t len = strlen(offered);
        snprintf(offered + len, sizeof offered - len, "%s%s", len ? ", " : "",
                 vf_fourcc_text(desc.pixelformat, text));
    }
    if (wanted == V4L2_PIX_FMT_YUYV && has_yuyv)
        *chosen = V4L2_PIX_FMT_YUYV;
    else if (has_mjpeg)
        *chosen = V4L2_PIX_FMT_MJPEG;
    else if (has_yuyv)
        *chosen = V4L2_PIX_FMT_YUYV;
    else
        return vf_fail(VF_EINPUT, "camera %s offers neither YUYV nor MJPEG (it offers: %s)",
                       cam->device, offered[0] ? offered : "nothing");
    return VF_OK;
}

/* S_FMT: ask for the format at the wanted size; the driver answers with what it will do. */
static vf_status set_format(vf_v4l2 *cam, uint32_t pixel_format, int width, int height)
{
    struct v4l2_format fmt;
    memset(&fmt, 0, sizeof fmt);
    fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if ((width <= 0 || height <= 0) && xioctl(cam, VIDIOC_G_FMT, &fmt) == 0) {
        width = (int)fmt.fmt.pix.width;
        height = (int)fmt.fmt.pix.height;
    }
    memset(&fmt, 0, sizeof fmt);
    fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    fmt.fmt.pix.width = width > 0 ? (uint32_t)width : 640;
    fmt.fmt.pix.height = height > 0 ? (uint32_t)height : 480;
    fmt.fmt.pix.pixelformat = pixel_format;
    fmt.fmt.pix.field = V4L2_FIELD_NONE;
    if (xioctl(cam, VIDIOC_S_FMT, &fmt) == -1)
        return vf_fail(VF_EINPUT, "camera %s refused its format (VIDIOC_S_FMT: %s)", cam->device,
                       strerror(errno));
    uint32_t got = fmt.fmt.pix.pixelformat;
    if (got != V4L2_PIX_FMT_MJPEG && got != V4L2_PIX_FMT_YUYV) {
        char text[5];
        return vf_fail(VF_EINPUT, "camera %s switched to pixel format %s, which is not supported",
                       cam->device, vf_fourcc_text(got, text));
    }
    if (fmt.fmt.pix.width == 0 || fmt.fmt.pix.height == 0 ||
        (got == V4L2_PIX_FMT_YUYV && fmt.fmt.pix.width % 2))
        return vf_fail(VF_EINPUT, "camera %s answered with an unusable size %ux%u", cam->device,
                       fmt.fmt.pix.width, fmt.fmt.pix.height);
    cam->info.pixel_format = got;
    cam->info.width = (int)fmt.fmt.pix.width;
    cam->info.height = (int)fmt.fmt.pix.height;
    cam->info.bytes_per_line = fmt.fmt.pix.bytesperline;
    if (got == V4L2_PIX_FMT_YUYV && cam->info.bytes_per_line < 2 * fmt.fmt.pix.width)
        cam->info.bytes_per_line = 2 * fmt.fmt.pix.width;
    return VF_OK;
}

/* G_PARM: the nominal frame rate, when the driver tells. */
static void read_frame_rate(vf_v4l2 *cam)
{
    struct v4l2_streamparm parm;
    memset(&parm, 0, sizeof parm);
    parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    const struct v4l2_fract *t = &parm.parm.capture.timeperframe;
    if (xioctl(cam, VIDIOC_G_PARM, &parm) == 0 &&
        (parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME) && t->numerator && t->denominator)
        cam->info.fps = (double)t->denominator / t->numerator;
}

/* ---- the public API ---- */

vf_status vf_v4l2_open(const char *device, const vf_v4l2_ops *ops, const vf_v4l2_request *request,
                       vf_v4l2 **out)
{
    vf_v4l2 *cam = calloc(1, sizeof *cam);
    if (!cam)
        return vf_fail(VF_EINTERNAL, "out of memory");
    cam->ops = ops ? *ops : *vf_v4l2_system_ops();
    snprintf(cam->device, sizeof cam->device, "%s", device);
    int buffers = request && request->buffer_count > 0 ? request->buffer_count : DEFAULT_BUFFERS;
    cam->wanted_buffers = buffers > MAX_BUFFERS ? MAX_BUFFERS : buffers;
    cam->fd = cam->ops.open(cam->ops.ctx, device, O_RDWR | O_NONBLOCK | O_CLOEXEC);
    if (cam->fd < 0) {
        vf_status status = open_error(device, errno);
        free(cam);
        return status;
    }
    uint32_t pixel_format = 0;
    vf_status status = check_capabilities(cam);
    if (status == VF_OK)
        status = choose_pixel_format(cam, request ? request->pixel_format : 0, &pixel_format);
    if (status == VF_OK)
        status = set_format(cam, pixel_format, request ? request->width : 0,
                            request ? request->height : 0);
    if (status != VF_OK) {
        vf_v4l2_close(cam);
        return status;
    }
    read_frame_rate(cam);
    *out = cam;
    return VF_OK;
}

const vf_v4l2_info *vf_v4l2_get_info(const vf_v4l2 *camera)
{
    return &camera->info;
}

static vf_status queue_buffer(vf_v4l2 *cam, uint32_t index)
{
    struct v4l2_buffer buf;
    memset(&buf, 0, sizeof buf);
    buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buf.memory = V4L2_MEMORY_MMAP;
    buf.index = index;
    if (xioctl(cam, VIDIOC_QBUF, &buf) == -1)
        return vf_fail(VF_EINPUT, "camera %s: cannot queue buffer %u (%s)", cam->device, index,
                       strerror(errno));
    return VF_OK;
}

/* QUERYBUF + mmap for every buffer the driver granted. */
static vf_status map_buffers(vf_v4l2 *cam, int count)
{
    for (int i = 0; i < count; i++) {
        struct v4l2_buffer buf;
        memset(&buf, 0, sizeof buf);
        buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        buf.memory = V4L2_MEMORY_MMAP;
        buf.index = (uint32_t)i;
        if (xioctl(cam, VIDIOC_QUERYBUF, &buf) == -1)
            return vf_fail(VF_EINPUT, "camera %s: cannot query buffer %d (%s)", cam->device, i,
                           strerror(errno));
        void *start = cam->ops.mmap(cam->ops.ctx, buf.length, PROT_READ | PROT_WRITE, MAP_SHARED,
                                    cam->fd, (off_t)buf.m.offset);
        if (start == MAP_FAILED)
            return vf_fail(VF_EINPUT, "camera %s: cannot map buffer %d (%s)", cam->device, i,
                           strerror(errno));
        cam->buffers[i] = (mapped_buffer){start, buf.length};
        cam->mapped_count = i + 1;
    }
    return VF_OK;
}

vf_status vf_v4l2_start(vf_v4l2 *cam)
{
    struct v4l2_requestbuffers req;
    memset(&req, 0, sizeof req);
    req.count = (uint32_t)cam->wanted_buffers;
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    if (xioctl(cam, VIDIOC_REQBUFS, &req) == -1)
        return vf_fail(VF_EINPUT, "camera %s cannot stream through mapped buffers (%s)",
                       cam->device, strerror(errno));
    if (req.count < 1)
        return vf_fail(VF_EINPUT, "camera %s granted no buffers", cam->device);
    int count = req.count > MAX_BUFFERS ? MAX_BUFFERS : (int)req.count;
    cam->info.buffer_count = count;
    vf_status status = map_buffers(cam, count);
    for (int i = 0; status == VF_OK && i < count; i++)
        status = queue_buffer(cam, (uint32_t)i);
    if (status != VF_OK)
        return status;
    enum v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (xioctl(cam, VIDIOC_STREAMON, &type) == -1)
        return vf_fail(VF_EINPUT, "camera %s will not start streaming (%s)", cam->device,
                       strerror(errno));
    cam->streaming = 1;
    return VF_OK;
}

/* poll until the device has a frame, then DQBUF it. */
static vf_status dequeue(vf_v4l2 *cam, int timeout_ms, struct v4l2_buffer *buf)
{
    for (;;) {
        struct pollfd pfd = {.fd = cam->fd, .events = POLLIN};
        int r = cam->ops.poll(cam->ops.ctx, &pfd, 1, timeout_ms);
        if (r == -1 && errno == EINTR)
            continue;
        if (r == -1)
            return vf_fail(VF_EINPUT, "camera %s: waiting for a frame failed (%s)", cam->device,
                           strerror(errno));
        if (r == 0)
            return vf_fail(VF_EINPUT, "camera %s sent no frame in %.1f s; is it covered or in use?",
                           cam->device, timeout_ms / 1000.0);
        if (pfd.revents & (POLLERR | POLLHUP | POLLNVAL))
            return vf_fail(VF_EINPUT, "camera %s stopped (unplugged?)", cam->device);
        memset(buf, 0, sizeof *buf);
        buf->type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        buf->memory = V4L2_MEMORY_MMAP;
        if (xioctl(cam, VIDIOC_DQBUF, buf) == 0)
            break;
        if (errno != EAGAIN)
            return vf_fail(VF_EINPUT, "camera %s: cannot take a frame (%s)", cam->device,
                           strerror(errno));
    }
    if ((int)buf->index >= cam->mapped_count)
        return vf_fail(VF_EINPUT, "camera %s returned an unknown buffer %u", cam->device,
                       buf->index);
    return VF_OK;
}

/* Convert the frame in a dequeued buffer to RGB. */
static vf_status convert(vf_v4l2 *cam, const struct v4l2_buffer *buf, vf_rgb8 *frame)
{
    const unsigned char *data = cam->buffers[buf->index].start;
    size_t length = cam->buffers[buf->index].length;
    size_t used = buf->bytesused && buf->bytesused <= length ? buf->bytesused : length;
    const vf_v4l2_info *info = &cam->info;
    if (info->pixel_format == V4L2_PIX_FMT_MJPEG)
        return vf_rgb8_decode(data, used, frame);
    if (used < (size_t)info->bytes_per_line * (size_t)info->height)
        return vf_fail(VF_EINPUT, "camera %s sent a short YUYV frame (%zu bytes)", cam->device,
                       used);
    vf_status status = vf_rgb8_resize_buffer(frame, info->width, info->height);
    if (status == VF_OK)
        vf_yuyv_to_rgb8(data, info->bytes_per_line, info->width, info->height, frame->data);
    return status;
}

vf_status vf_v4l2_read(vf_v4l2 *cam, int timeout_ms, vf_rgb8 *frame, uint32_t *sequence)
{
    if (!cam->streaming)
        return vf_fail(VF_EINTERNAL, "camera %s is not streaming", cam->device);
    for (int bad = 0; bad < MAX_BAD_FRAMES; bad++) {
        struct v4l2_buffer buf;
        vf_status status = dequeue(cam, timeout_ms, &buf);
        if (status != VF_OK)
            return status;
        if (!(buf.flags & V4L2_BUF_FLAG_ERROR))
            status = convert(cam, &buf, frame);
        /* The buffer goes back to the driver whatever became of its frame. */
        vf_status requeued = queue_buffer(cam, buf.index);
        if (requeued != VF_OK)
            return requeued;
        if (status == VF_OK && !(buf.flags & V4L2_BUF_FLAG_ERROR)) {
            if (sequence)
                *sequence = buf.sequence;
            return VF_OK;
        }
        if (status == VF_EINTERNAL)
            return status;
    }
    return vf_fail(VF_EINPUT, "camera %s sent %d corrupt frames in a row", cam->device,
                   MAX_BAD_FRAMES);
}

void vf_v4l2_close(vf_v4l2 *cam)
{
    if (!cam)
        return;
    if (cam->streaming) {
        enum v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        xioctl(cam, VIDIOC_STREAMOFF, &type);
    }
    for (int i = 0; i < cam->mapped_count; i++)
        cam->ops.munmap(cam->ops.ctx, cam->buffers[i].start, cam->buffers[i].length);
    if (cam->info.buffer_count > 0) { /* give the buffers back to the driver */
        struct v4l2_requestbuffers req;
        memset(&req, 0, sizeof req);
        req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        req.memory = V4L2_MEMORY_MMAP;
        xioctl(cam, VIDIOC_REQBUFS, &req);
    }
    cam->ops.close(cam->ops.ctx, cam->fd);
    free(cam);
}

/* ---- YUYV to RGB ---- */

static inline unsigned char clamp_shift(int v)
{
    v = v < 0 ? 0 : v >> 8;
    return (unsigned char)(v > 255 ? 255 : v);
}

void vf_yuyv_to_rgb8(const unsigned char *yuyv, size_t stride, int width, int height,
                     unsigned char *rgb)
{
    /* BT.601 limited range in 8-bit fixed point: R = 1.164 (Y - 16) + 1.596 (V - 128), ... */
    for (int y = 0; y < height; y++) {
        const unsigned char *s = yuyv + (size_t)y * stride;
        unsigned char *d = rgb + (size_t)y * (size_t)width * 3;
        for (int x = 0; x + 1 < width; x += 2, s += 4, d += 6) {
            /* The two pixels of a sample share its chroma: U (Cb) and V (Cr). */
            int u = s[1] - 128, v = s[3] - 128;
            int red = 409 * v, green = -100 * u - 208 * v, blue = 516 * u;
            for (int k = 0; k < 2; k++) {
                int luma = 298 * (s[2 * k] - 16) + 128;
                d[3 * k + 0] = clamp_shift(luma + red);
                d[3 * k + 1] = clamp_shift(luma + green);
                d[3 * k + 2] = clamp_shift(luma + blue);
            }
        }
    }
}
