/* Parsing picked image points, "NAME:U,V;NAME:U,V" (vf/calib.h). */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "vf/calib.h"

static vf_status parse_one(const char *item, size_t length, vf_pick *pick)
{
    char text[256];
    if (length >= sizeof text)
        return vf_fail(VF_EINPUT, "pick '%.40s...' is too long", item);
    memcpy(text, item, length);
    text[length] = '\0';
    char *colon = strrchr(text, ':');
    if (!colon || colon == text || (size_t)(colon - text) >= sizeof pick->frame)
        return vf_fail(VF_EINPUT, "pick '%s' is not FRAME:U,V (for example frame_0003.jpg:812,433)",
                       text);
    *colon = '\0';
    char *end;
    errno = 0;
    pick->u = strtod(colon + 1, &end);
    int ok = end != colon + 1 && *end == ',' && !errno;
    const char *v = end + 1;
    if (ok) {
        pick->v = strtod(v, &end);
        ok = end != v && *end == '\0' && !errno && pick->u >= 0 && pick->v >= 0;
    }
    if (!ok)
        return vf_fail(VF_EINPUT, "pick '%s:%s' needs pixel coordinates U,V (for example "
                                  "frame_0003.jpg:812,433)",
                       text, colon + 1);
    memcpy(pick->frame, text, (size_t)(colon - text) + 1); /* fits: checked above */
    return VF_OK;
}

vf_status vf_parse_picks(const char *text, vf_pick *picks, int max, int *count)
{
    *count = 0;
    const char *p = text;
    while (*p) {
        const char *end = strchr(p, ';');
        size_t length = end ? (size_t)(end - p) : strlen(p);
        if (length > 0) {
            if (*count == max)
                return vf_fail(VF_EINPUT, "more than %d picks of one point", max);
            vf_status status = parse_one(p, length, &picks[*count]);
            if (status != VF_OK)
                return status;
            (*count)++;
        }
        p += length + (end ? 1 : 0);
    }
    if (*count < 2)
        return vf_fail(VF_EINPUT, "a point must be picked in at least two frames: "
                                  "\"FRAME:U,V;FRAME2:U,V\", got '%s'",
                       text);
    return VF_OK;
}
