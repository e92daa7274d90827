/* The original ArUco code (vf/calib.h): a 5 x 5 grid, each row one of four 5-bit words that
 * carries two bits of the id (ten bits, ids 0..1023), most significant pair in the top row.
 * The words are far enough apart (and none reads as another backwards) that a marker decodes
 * in exactly one of its four orientations. OpenCV calls this dictionary DICT_ARUCO_ORIGINAL. */
#include <string.h>

#include "vf/calib.h"

static const unsigned char row_words[4] = {0x10, 0x17, 0x09, 0x0e}; /* 1 = white */

int vf_aruco_decode(const unsigned char bits[25])
{
    int id = 0;
    for (int y = 0; y < 5; y++) {
        int word = 0;
        for (int x = 0; x < 5; x++)
            word = (word << 1) | (bits[5 * y + x] ? 1 : 0);
        int pair = -1;
        for (int k = 0; k < 4; k++)
            if (row_words[k] == word)
                pair = k;
        if (pair < 0)
            return -1;
        id = (id << 2) | pair;
    }
    return id;
}

vf_status vf_aruco_image(int id, int cell_px, vf_rgb8 *out)
{
    if (id < 0 || id >= VF_ARUCO_IDS || cell_px < 1)
        return vf_fail(VF_EINPUT, "ArUco ids run from 0 to %d", VF_ARUCO_IDS - 1);
    int side = 9 * cell_px; /* a white cell of margin, the black border, the 5 x 5 code */
    vf_status status = vf_rgb8_resize_buffer(out, side, side);
    if (status != VF_OK)
        return status;
    for (int y = 0; y < side; y++)
        for (int x = 0; x < side; x++) {
            int cx = x / cell_px - 2, cy = y / cell_px - 2; /* code cell, -2/-1 outside */
            int white = 1;
            if (cx >= -1 && cy >= -1 && cx <= 5 && cy <= 5) {
                white = 0; /* the black border */
                if (cx >= 0 && cy >= 0 && cx < 5 && cy < 5) {
                    int word = row_words[(id >> (2 * (4 - cy))) & 3];
                    white = (word >> (4 - cx)) & 1;
                }
            }
            memset(out->data + 3 * ((size_t)y * side + x), white ? 255 : 0, 3);
        }
    return VF_OK;
}
