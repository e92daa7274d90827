/* pipeline/calib_cmd.h: the subcommands of `vfcapture calib` (one file each). */
#ifndef VF_PIPELINE_CALIB_CMD_H
#define VF_PIPELINE_CALIB_CMD_H

#include "cli.h"
#include "vf/calib.h"

int calib_intrinsics(int argc, char **argv);
int calib_scale(int argc, char **argv);

/* "9x6" into board->cols, rows (inner corners, each 2..100). */
#define CALIB_DEFAULT_DICTIONARY "6x6_250" /* ChArUco markers, as OpenCV's samples print */

vf_status calib_parse_board(const char *text, vf_calib_board *board);
/* A positive length in millimetres, returned in metres; `what` names the option. */
vf_status calib_parse_mm(const char *text, const char *what, double *metres);

#endif
