/* vf/v4l2.h: capturing frames from a Linux webcam through V4L2 (Video4Linux2).
 *
 * The device is driven with the V4L2 ioctls directly: QUERYCAP to check it is a streaming
 * capture device, ENUM_FMT and S_FMT to agree on YUYV or MJPEG at a size, REQBUFS/QUERYBUF and
 * mmap for a ring of driver buffers, QBUF/STREAMON, then poll + DQBUF for each frame, which is
 * converted to RGB and its buffer queued again at once.
 *
 * Every call that reaches the device goes through a vf_v4l2_ops table: the real system calls
 * by default (vf_v4l2_system_ops), or an in-process fake device in the tests (no camera or
 * kernel module is needed, and LD_PRELOAD could not catch libv4l2's raw syscalls anyway).
 *
 * A vf_v4l2 is opened by vf_v4l2_open and released by vf_v4l2_close, which stops streaming,
 * unmaps the buffers and closes the device. The ops table must outlive it. */
#ifndef VF_V4L2_H
#define VF_V4L2_H

#include <poll.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>

#include "vf/error.h"
#include "vf/rgb8.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Device access. Each function behaves like the system call of the same name (return value,
 * errno); ctx is passed through untouched. */
typedef struct vf_v4l2_ops {
    void *ctx;
    int (*open)(void *ctx, const char *path, int flags);
    int (*close)(void *ctx, int fd);
    int (*ioctl)(void *ctx, int fd, unsigned long request, void *arg);
    void *(*mmap)(void *ctx, size_t length, int prot, int flags, int fd, off_t offset);
    int (*munmap)(void *ctx, void *addr, size_t length);
    int (*poll)(void *ctx, struct pollfd *fds, nfds_t count, int timeout_ms);
} vf_v4l2_ops;

/* How long a read waits for a webcam that sends nothing before failing: it has stopped. Every
 * caller of vf_v4l2_read uses this one value. */
#define VF_CAMERA_TIMEOUT_MS 5000

/* The real system calls. */
const vf_v4l2_ops *vf_v4l2_system_ops(void);

typedef struct vf_v4l2_request {
    int width, height;     /* wanted frame size; 0 x 0 keeps the device's current size */
    uint32_t pixel_format; /* V4L2_PIX_FMT_MJPEG or _YUYV to prefer one; 0: MJPEG, then YUYV */
    int buffer_count;      /* driver buffers to ask for; 0: 4 */
} vf_v4l2_request;

typedef struct vf_v4l2_info {
    char driver[16], card[32];
    int width, height;     /* the size the device agreed to */
    uint32_t pixel_format; /* V4L2_PIX_FMT_MJPEG or V4L2_PIX_FMT_YUYV */
    uint32_t bytes_per_line;
    double fps;            /* nominal frame rate (0 when the driver does not say) */
    int buffer_count;      /* buffers granted (after vf_v4l2_start) */
} vf_v4l2_info;

typedef struct vf_v4l2 vf_v4l2;

/* Open a capture device and agree on a format: the requested pixel format when the device
 * offers it, else the other supported one; the size the driver picks nearest the request.
 * VF_EINPUT with one line naming the device when it does not exist, cannot be opened, is not
 * a V4L2 streaming capture device, or offers neither YUYV nor MJPEG. ops NULL: system calls. */
vf_status vf_v4l2_open(const char *device, const vf_v4l2_ops *ops, const vf_v4l2_request *request,
                       vf_v4l2 **out);

/* What was agreed (borrowed; valid until vf_v4l2_close). */
const vf_v4l2_info *vf_v4l2_get_info(const vf_v4l2 *camera);

/* Map the buffers, queue them and start streaming. */
vf_status vf_v4l2_start(vf_v4l2 *camera);

/* Wait up to timeout_ms for the next frame, convert it to RGB into *frame (reuses it, see
 * vf/rgb8.h) and hand its buffer back to the driver. *sequence (may be NULL) gets the
 * driver's frame number. Frames the driver marks as corrupt are skipped. */
vf_status vf_v4l2_read(vf_v4l2 *camera, int timeout_ms, vf_rgb8 *frame, uint32_t *sequence);

/* Stop streaming, unmap, close; NULL is fine. */
void vf_v4l2_close(vf_v4l2 *camera);

/* Convert packed YUYV 4:2:2 (BT.601, limited range, as webcams send it) to RGB.
 * stride: bytes per source row (at least 2 * width); width must be even. */
void vf_yuyv_to_rgb8(const unsigned char *yuyv, size_t stride, int width, int height,
                     unsigned char *rgb);

/* A FourCC as text ("YUYV"); out holds 5 bytes. */
const char *vf_fourcc_text(uint32_t fourcc, char out[5]);

#ifdef __cplusplus
}
#endif
#endif
