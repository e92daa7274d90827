/* vf/overlay.h: a live window for guided capture: camera frames with lines of text drawn over
 * them (OpenCV highgui, src/physical/overlay_cv.cpp). Opened only where a display exists; the
 * drawing itself works anywhere (and is what the tests check).
 *
 * Memory: vf_overlay_draw fills `out` (reused); a window is released with vf_overlay_close. */
#ifndef VF_OVERLAY_H
#define VF_OVERLAY_H

#include "vf/error.h"
#include "vf/rgb8.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Whether a window can be shown: a local X display named by $DISPLAY (":N") whose socket
 * exists. highgui ends the process when it cannot connect, so this is checked first, and a
 * remote display gets no window. */
int vf_overlay_available(void);

/* The frame with `lines` of text on a dark band along its top, and a green border when
 * `highlight` (on target) or a grey one when not. */
vf_status vf_overlay_draw(const vf_rgb8 *frame, const char *const *lines, int count,
                          int highlight, vf_rgb8 *out);

typedef struct vf_overlay vf_overlay;

vf_status vf_overlay_open(const char *title, vf_overlay **out);

/* Draw and show a frame; *quit becomes 1 when the person pressed q or Esc in the window. */
vf_status vf_overlay_show(vf_overlay *window, const vf_rgb8 *frame, const char *const *lines,
                          int count, int highlight, int *quit);

void vf_overlay_close(vf_overlay *window);

#ifdef __cplusplus
}
#endif
#endif
