/* vfcapture calib: camera calibration (intrinsics from a checkerboard), a workspace's metric
 * scale, and the printable board and markers they need. Dispatches to calib_intrinsics.c and
 * calib_scale.c; the printouts are here. */
#include <stdlib.h>
#include <string.h>

#include "calib_cmd.h"
#include "vf/log.h"

static const char usage[] =
    "usage: vfcapture calib <intrinsics|scale|board|marker> [options]\n"
    "\n"
    "  intrinsics (VIDEO | DIR | --v4l2 DEV) --board COLSxROWS --square MM [-o camera.json]\n"
    "             calibrate a camera from views of a checkerboard (or ChArUco board,\n"
    "             --charuco MM); the camera file feeds\n"
    "             'vfcapture poses --camera'\n"
    "  scale WS (--marker ID --marker-size MM | --distance P1 P2 MM)\n"
    "             give a posed workspace metric scale (WS/calib/scale.json)\n"
    "  board --board COLSxROWS -o board.png [--square-px N] [--charuco [--dict NAME]]\n"
    "             write a printable checkerboard or ChArUco board\n"
    "  marker --id ID -o marker.png [--cell-px N]\n"
    "             write a printable ArUco marker (original dictionary, ids 0..1023)\n"
    "\n"
    "'vfcapture calib <subcommand> --help' for details.\n";

enum { OPT_BOARD = CLI_OPT_FIRST_CUSTOM, OPT_ID, OPT_PX, OPT_CHARUCO, OPT_DICT };

/* `calib board` and `calib marker`: write a printable pattern. */
static int print_pattern(int argc, char **argv, int marker)
{
    const char *name = marker ? "calib marker" : "calib board";
    const char *help = marker
                           ? "usage: vfcapture calib marker --id ID -o FILE.png [--cell-px N]\n"
                             "\n"
                             "Write ArUco marker ID (original dictionary, 0..1023; OpenCV's\n"
                             "DICT_ARUCO_ORIGINAL) as a PNG: 7 x 7 cells with a white margin.\n"
                             "Print it flat; its size for 'calib scale --marker-size' is the side of\n"
                             "the black square.\n"
                             "\n"
                             "options:\n"
                             "      --id ID       the marker's id\n"
                             "  -o, --output FILE the PNG to write\n"
                             "      --cell-px N   pixels per cell (default 40)\n" CLI_COMMON_HELP
                           : "usage: vfcapture calib board --board COLSxROWS -o FILE.png "
                             "[--square-px N] [--charuco [--dict NAME]]\n"
                             "\n"
                             "Write a checkerboard with COLSxROWS inner corners ((COLS+1) x\n"
                             "(ROWS+1) squares) as a PNG, with a white margin. Print it flat and\n"
                             "measure one square for 'calib intrinsics --square' (and, on a\n"
                             "ChArUco board, one marker for --charuco: 3/4 of the square).\n"
                             "\n"
                             "options:\n"
                             "      --board CxR   inner corners, e.g. 9x6\n"
                             "  -o, --output FILE the PNG to write\n"
                             "      --square-px N pixels per square (default 100)\n"
                             "      --charuco     put ArUco markers in the white squares\n"
                             "      --dict NAME   their dictionary (default " CALIB_DEFAULT_DICTIONARY
                             ")\n" CLI_COMMON_HELP;
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        {"board", required_argument, NULL, OPT_BOARD},
        {"id", required_argument, NULL, OPT_ID},
        {"square-px", required_argument, NULL, OPT_PX},
        {"cell-px", required_argument, NULL, OPT_PX},
        {"charuco", no_argument, NULL, OPT_CHARUCO},
        {"dict", required_argument, NULL, OPT_DICT},
        {"output", required_argument, NULL, 'o'},
        {0, 0, 0, 0},
    };
    cli_flags flags = {0};
    vf_calib_board board = {0, 0, 1, 0, 0};
    const char *output = NULL;
    long id = -1, px = marker ? 40 : 100;
    int c;
    vf_status status = vf_charuco_dictionary(CALIB_DEFAULT_DICTIONARY, &board.dictionary);
    while (status == VF_OK &&
           (c = getopt_long(argc, argv, CLI_COMMON_SHORT "o:", longopts, NULL)) != -1) {
        if (cli_common_option(c, &flags, name, help))
            continue;
        if (c == 'o')
            output = optarg;
        else if (c == OPT_BOARD && !marker)
            status = calib_parse_board(optarg, &board);
        else if (c == OPT_CHARUCO && !marker)
            board.marker = VF_CHARUCO_MARKER_RATIO * board.square;
        else if (c == OPT_DICT && !marker)
            status = vf_charuco_dictionary(optarg, &board.dictionary);
        else if (c == OPT_ID && marker)
            status = cli_count("--id", optarg, 0, VF_ARUCO_IDS - 1, &id);
        else if (c == OPT_PX)
            status = cli_count(marker ? "--cell-px" : "--square-px", optarg, 4, 1000, &px);
        else if (marker ? c == OPT_BOARD || c == OPT_CHARUCO || c == OPT_DICT : c == OPT_ID)
            status = vf_fail(VF_EINPUT, "see 'vfcapture %s --help' for the options", name);
    }
    if (status == VF_OK && (optind != argc || !output))
        status = vf_fail(VF_EINPUT, "give the output file with -o FILE.png (see 'vfcapture %s "
                                    "--help')", name);
    if (status == VF_OK && (marker ? id < 0 : board.cols == 0))
        status = vf_fail(VF_EINPUT, marker ? "give the marker's --id" : "give --board COLSxROWS");
    vf_rgb8 img = {0};
    if (status == VF_OK)
        status = marker ? vf_aruco_image((int)id, (int)px, &img)
                        : vf_calib_board_image(&board, (int)px, &img);
    if (status == VF_OK)
        status = vf_rgb8_save(output, &img);
    vf_rgb8_free(&img);
    if (status != VF_OK)
        return cli_fail(name, status);
    if (flags.json)
        cli_print_json(json_pack("{s:s}", "output", output));
    else
        vf_info("wrote %s", output);
    return 0;
}

int cmd_calib(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "-h") || !strcmp(argv[1], "--help")) {
        fputs(usage, argc < 2 ? stderr : stdout);
        return argc < 2 ? 1 : 0;
    }
    const char *sub = argv[1];
    if (!strcmp(sub, "intrinsics"))
        return calib_intrinsics(argc - 1, argv + 1);
    if (!strcmp(sub, "scale"))
        return calib_scale(argc - 1, argv + 1);
    if (!strcmp(sub, "board") || !strcmp(sub, "marker"))
        return print_pattern(argc - 1, argv + 1, !strcmp(sub, "marker"));
    fprintf(stderr, "vfcapture calib: error: unknown subcommand '%s': use intrinsics, scale, "
                    "board or marker\n",
            sub);
    return 1;
}
