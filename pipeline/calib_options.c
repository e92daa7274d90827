/* Option values the calib subcommands share (calib_cmd.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib_cmd.h"

vf_status calib_parse_board(const char *text, vf_calib_board *board)
{
    int cols, rows;
    if (cli_size("--board", text, &cols, &rows) != VF_OK || cols < 2 || rows < 2 || cols > 100 ||
        rows > 100)
        return vf_fail(VF_EINPUT, "--board wants the inner corners as COLSxROWS from 2x2 to "
                                  "100x100, e.g. 9x6 for a board of 10 x 7 squares, not '%s'",
                       text);
    board->cols = cols;
    board->rows = rows;
    return VF_OK;
}

vf_status calib_parse_mm(const char *text, const char *what, double *metres)
{
    double mm;
    if (cli_number_above(what, text, 0, 1e6, &mm) != VF_OK)
        return VF_EINPUT; /* a length in millimetres */
    *metres = mm / 1000.0;
    return VF_OK;
}
