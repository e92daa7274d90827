/* Option values the calib subcommands share (calib_cmd.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib_cmd.h"

vf_status calib_parse_board(const char *text, vf_calib_board *board)
{
    char *end;
    long cols = strtol(text, &end, 10), rows = 0;
    if (*end == 'x' || *end == 'X') {
        const char *second = end + 1;
        rows = strtol(second, &end, 10);
        if (end == second)
            rows = 0;
    }
    if (*end || cols < 2 || rows < 2 || cols > 100 || rows > 100)
        return vf_fail(VF_EINPUT, "--board: give the inner corners as COLSxROWS, e.g. 9x6 for a "
                                  "board of 10 x 7 squares");
    board->cols = (int)cols;
    board->rows = (int)rows;
    return VF_OK;
}

vf_status calib_parse_mm(const char *text, const char *what, double *metres)
{
    double mm;
    if (cli_parse_doubles(text, &mm, 1) != 1 || !(mm > 0) || mm > 1e6)
        return vf_fail(VF_EINPUT, "%s: give a length in millimetres, e.g. 25", what);
    *metres = mm / 1000.0;
    return VF_OK;
}
