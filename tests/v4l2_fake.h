/* tests/v4l2_fake.h: an in-process V4L2 camera for the tests, behind vf_v4l2_ops.
 *
 * It answers the ioctls vf/v4l2.h uses the way a UVC webcam driver does: QUERYCAP, ENUM_FMT
 * over a configurable list of pixel formats, S_FMT (the one size it has; an unknown pixel
 * format falls back to its first), G_PARM (30 fps), REQBUFS/QUERYBUF with the buffers in a
 * memfd that the real mmap maps, QBUF/DQBUF as a FIFO that fills each buffer with the next
 * recorded frame as it is taken, STREAMON/OFF. poll() is ready whenever a buffer is queued
 * (a camera that never makes you wait), and reports a timeout when none is, which is what a
 * caller that forgets to re-queue its buffers runs into. It counts what it was asked to do so
 * the tests can check buffers are re-queued, unmapped and the device closed.
 *
 * Header-only (static functions) because each test program is built from one .c file;
 * include it first (it needs _GNU_SOURCE for memfd_create). */
#ifndef VF_TEST_V4L2_FAKE_H
#define VF_TEST_V4L2_FAKE_H

#define _GNU_SOURCE
#include <errno.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "vf/v4l2.h"

#define FAKE_MAX_BUFFERS 8

typedef struct fake_camera {
    /* Set by the test. */
    const char *path;        /* the device node it answers to */
    int not_capture;         /* a metadata node: QUERYCAP without VIDEO_CAPTURE */
    uint32_t formats[4];     /* what ENUM_FMT lists */
    int format_count;
    int width, height;       /* the only size it has */
    int frame_count;         /* recorded frames, played in a loop */
    unsigned char **yuyv;    /* per frame: width * 2 * height bytes */
    unsigned char **mjpeg;   /* per frame: a JPEG of mjpeg_size[i] bytes */
    size_t *mjpeg_size;
    long corrupt_sequence;   /* this frame number comes flagged V4L2_BUF_FLAG_ERROR (-1: none) */
    /* State. */
    int fd;
    uint32_t fourcc;
    int streaming;
    int buffer_count;
    size_t buffer_size;
    int queue[FAKE_MAX_BUFFERS]; /* buffers the "driver" holds, oldest first */
    int queued;
    uint32_t sequence;
    /* What it was asked to do. */
    int opens, closes, maps, unmaps, qbufs, dqbufs;
    uint32_t asked_fourcc;
} fake_camera;

/* A camera at `path` offering `count` formats at width x height, no frames yet. */
static void fake_init(fake_camera *cam, const char *path, const uint32_t *formats, int count,
                      int width, int height)
{
    memset(cam, 0, sizeof *cam);
    cam->path = path;
    cam->format_count = count;
    memcpy(cam->formats, formats, sizeof *formats * (size_t)count);
    cam->width = width;
    cam->height = height;
    cam->fd = -1;
    cam->corrupt_sequence = -1;
}

static int fake_fail(int err)
{
    errno = err;
    return -1;
}

static int fake_open(void *ctx, const char *path, int flags)
{
    fake_camera *cam = ctx;
    (void)flags;
    if (strcmp(path, cam->path) != 0)
        return fake_fail(ENOENT);
    cam->fd = memfd_create("fake-video", MFD_CLOEXEC);
    cam->opens++;
    return cam->fd;
}

static int fake_close(void *ctx, int fd)
{
    fake_camera *cam = ctx;
    cam->closes++;
    cam->fd = -1;
    return close(fd);
}

static int fake_offers(const fake_camera *cam, uint32_t fourcc)
{
    for (int i = 0; i < cam->format_count; i++)
        if (cam->formats[i] == fourcc)
            return 1;
    return 0;
}

static void fake_fill_format(const fake_camera *cam, struct v4l2_format *fmt)
{
    fmt->fmt.pix.width = (uint32_t)cam->width;
    fmt->fmt.pix.height = (uint32_t)cam->height;
    fmt->fmt.pix.pixelformat = cam->fourcc;
    fmt->fmt.pix.field = V4L2_FIELD_NONE;
    fmt->fmt.pix.bytesperline = cam->fourcc == V4L2_PIX_FMT_YUYV ? 2 * (uint32_t)cam->width : 0;
    fmt->fmt.pix.sizeimage = 2 * (uint32_t)cam->width * (uint32_t)cam->height;
}

static int fake_querycap(fake_camera *cam, struct v4l2_capability *cap)
{
    memset(cap, 0, sizeof *cap);
    snprintf((char *)cap->driver, sizeof cap->driver, "fake");
    snprintf((char *)cap->card, sizeof cap->card, "Fake Camera");
    uint32_t node = cam->not_capture ? V4L2_CAP_META_CAPTURE
                                     : V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
    cap->device_caps = node;
    cap->capabilities = node | V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING | V4L2_CAP_DEVICE_CAPS;
    return 0;
}

static int fake_reqbufs(fake_camera *cam, struct v4l2_requestbuffers *req)
{
    if (req->memory != V4L2_MEMORY_MMAP)
        return fake_fail(EINVAL);
    if (cam->streaming)
        return fake_fail(EBUSY);
    cam->buffer_count = req->count > FAKE_MAX_BUFFERS ? FAKE_MAX_BUFFERS : (int)req->count;
    long page = sysconf(_SC_PAGESIZE);
    size_t frame = 2 * (size_t)cam->width * (size_t)cam->height;
    cam->buffer_size = (frame + (size_t)page - 1) / (size_t)page * (size_t)page;
    if (ftruncate(cam->fd, (off_t)(cam->buffer_size * (size_t)cam->buffer_count)) != 0)
        return -1;
    req->count = (uint32_t)cam->buffer_count;
    cam->queued = 0;
    return 0;
}

static int fake_qbuf(fake_camera *cam, struct v4l2_buffer *buf)
{
    if ((int)buf->index >= cam->buffer_count)
        return fake_fail(EINVAL);
    for (int i = 0; i < cam->queued; i++)
        if (cam->queue[i] == (int)buf->index)
            return fake_fail(EINVAL); /* queued twice */
    cam->queue[cam->queued++] = (int)buf->index;
    cam->qbufs++;
    return 0;
}

/* Hand out the oldest queued buffer, filled with the next recorded frame. */
static int fake_dqbuf(fake_camera *cam, struct v4l2_buffer *buf)
{
    if (!cam->streaming)
        return fake_fail(EINVAL);
    if (cam->queued == 0 || cam->frame_count == 0)
        return fake_fail(EAGAIN);
    int index = cam->queue[0];
    memmove(cam->queue, cam->queue + 1, sizeof(int) * (size_t)--cam->queued);
    int frame = (int)(cam->sequence % (uint32_t)cam->frame_count);
    const void *data = cam->fourcc == V4L2_PIX_FMT_YUYV ? cam->yuyv[frame] : cam->mjpeg[frame];
    size_t size = cam->fourcc == V4L2_PIX_FMT_YUYV ? 2 * (size_t)cam->width * cam->height
                                                    : cam->mjpeg_size[frame];
    off_t offset = (off_t)(cam->buffer_size * (size_t)index);
    if (size > cam->buffer_size || pwrite(cam->fd, data, size, offset) != (ssize_t)size)
        return fake_fail(EIO);
    memset(buf, 0, sizeof *buf);
    buf->type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buf->memory = V4L2_MEMORY_MMAP;
    buf->index = (uint32_t)index;
    buf->bytesused = (uint32_t)size;
    buf->length = (uint32_t)cam->buffer_size;
    buf->m.offset = (uint32_t)offset;
    buf->flags = V4L2_BUF_FLAG_DONE;
    if ((long)cam->sequence == cam->corrupt_sequence)
        buf->flags |= V4L2_BUF_FLAG_ERROR;
    buf->sequence = cam->sequence++;
    cam->dqbufs++;
    return 0;
}

static int fake_ioctl(void *ctx, int fd, unsigned long request, void *arg)
{
    fake_camera *cam = ctx;
    if (fd != cam->fd)
        return fake_fail(EBADF);
    switch (request) {
    case VIDIOC_QUERYCAP:
        return fake_querycap(cam, arg);
    case VIDIOC_ENUM_FMT: {
        struct v4l2_fmtdesc *desc = arg;
        if (desc->index >= (uint32_t)cam->format_count)
            return fake_fail(EINVAL);
        desc->pixelformat = cam->formats[desc->index];
        return 0;
    }
    case VIDIOC_G_FMT:
        fake_fill_format(cam, arg);
        return 0;
    case VIDIOC_S_FMT: {
        struct v4l2_format *fmt = arg;
        if (cam->streaming)
            return fake_fail(EBUSY);
        cam->asked_fourcc = fmt->fmt.pix.pixelformat;
        cam->fourcc = fake_offers(cam, cam->asked_fourcc) ? cam->asked_fourcc : cam->formats[0];
        fake_fill_format(cam, fmt);
        return 0;
    }
    case VIDIOC_G_PARM: {
        struct v4l2_streamparm *parm = arg;
        parm->parm.capture.capability = V4L2_CAP_TIMEPERFRAME;
        parm->parm.capture.timeperframe = (struct v4l2_fract){1, 30};
        return 0;
    }
    case VIDIOC_REQBUFS:
        return fake_reqbufs(cam, arg);
    case VIDIOC_QUERYBUF: {
        struct v4l2_buffer *buf = arg;
        if ((int)buf->index >= cam->buffer_count)
            return fake_fail(EINVAL);
        buf->length = (uint32_t)cam->buffer_size;
        buf->m.offset = (uint32_t)(cam->buffer_size * buf->index);
        return 0;
    }
    case VIDIOC_QBUF:
        return fake_qbuf(cam, arg);
    case VIDIOC_DQBUF:
        return fake_dqbuf(cam, arg);
    case VIDIOC_STREAMON:
        if (cam->buffer_count == 0)
            return fake_fail(EINVAL);
        cam->streaming = 1;
        return 0;
    case VIDIOC_STREAMOFF:
        cam->streaming = 0;
        cam->queued = 0;
        return 0;
    default:
        return fake_fail(ENOTTY);
    }
}

static void *fake_mmap(void *ctx, size_t length, int prot, int flags, int fd, off_t offset)
{
    fake_camera *cam = ctx;
    cam->maps++;
    return mmap(NULL, length, prot, flags, fd, offset);
}

static int fake_munmap(void *ctx, void *addr, size_t length)
{
    fake_camera *cam = ctx;
    cam->unmaps++;
    return munmap(addr, length);
}

static int fake_poll(void *ctx, struct pollfd *fds, nfds_t count, int timeout_ms)
{
    fake_camera *cam = ctx;
    (void)timeout_ms;
    for (nfds_t i = 0; i < count; i++)
        fds[i].revents = cam->streaming && cam->queued > 0 ? POLLIN : 0;
    return cam->streaming && cam->queued > 0 ? 1 : 0; /* 0: "timed out" at once */
}

static vf_v4l2_ops fake_ops(fake_camera *cam)
{
    vf_v4l2_ops ops = {cam, fake_open, fake_close, fake_ioctl, fake_mmap, fake_munmap, fake_poll};
    return ops;
}

#endif
