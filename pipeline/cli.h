/* pipeline/cli.h: what every stage command shares.
 *
 * Each command is `int cmd_<name>(int argc, char **argv)` (argv[0] is the command name) and
 * returns the process exit code: 0 ok, 1 bad input, 2 internal failure (vf_status values).
 * Options are getopt_long style; --help, --quiet and --json mean the same everywhere. */
#ifndef VF_PIPELINE_CLI_H
#define VF_PIPELINE_CLI_H

#include <getopt.h>
#include <jansson.h>
#include <stdint.h>
#include <stdio.h>

#include "vf/error.h"
#include "vf/field.h"
#include "vf/workspace.h"

/* The long options every command accepts; put CLI_COMMON_OPTIONS first in its table. */
enum { CLI_OPT_JSON = 1000, CLI_OPT_ENGINE, CLI_OPT_ATTACK, CLI_OPT_FIRST_CUSTOM = 1100 };
#define CLI_COMMON_OPTIONS                                                                 \
    {"help", no_argument, NULL, 'h'}, {"quiet", no_argument, NULL, 'q'},                   \
        {"json", no_argument, NULL, CLI_OPT_JSON}
#define CLI_COMMON_SHORT "hq"
#define CLI_COMMON_HELP                                                                    \
    "  -q, --quiet        no progress or info messages (warnings and errors still show)\n" \
    "      --json         print the result as one JSON document on stdout\n"              \
    "  -h, --help         show this help\n"

/* Commands that classify also put CLI_ENGINE_OPTION in their table and CLI_ENGINE_HELP in
 * their help; cli_common_option applies it to the whole process (vf_classifier_set_engine). */
#define CLI_ENGINE_OPTION {"engine", required_argument, NULL, CLI_OPT_ENGINE}
#define CLI_ENGINE_HELP                                                                        \
    "      --engine E     classifier engine: auto (default: onnxruntime when installed, else\n" \
    "                     opencv), onnxruntime or opencv; also $VF_ENGINE\n"

/* Commands that read an attack (and attack itself, which names the one it makes) put
 * CLI_ATTACK_OPTION in their table and handle CLI_OPT_ATTACK: the attack's name. */
#define CLI_ATTACK_OPTION {"attack", required_argument, NULL, CLI_OPT_ATTACK}
#define CLI_ATTACK_HELP                                                                         \
    "      --attack NAME      which of the workspace's attacks (WS/attack/NAME/); needed only\n" \
    "                         when it has several\n"

typedef struct cli_flags {
    int json;
    int quiet;
} cli_flags;

typedef struct cli_command {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
} cli_command;

/* Handle a common option. Returns 1 when `opt` was one (and applied), 0 when it is the
 * command's own. A --help prints `usage` to stdout and exits 0; an unknown option prints a
 * hint and exits 1. */
int cli_common_option(int opt, cli_flags *flags, const char *command, const char *usage);

/* A spelling kept from before the option vocabulary was made one (README, "Options"): warn
 * once, "vfcapture COMMAND: OLD is deprecated: use NEW", and go on with its meaning. */
void cli_deprecated(const char *command, const char *old, const char *now);

/* Print "vfcapture COMMAND: error: <message>" for the current vf error and return status. */
int cli_fail(const char *command, vf_status status);

/* Print a JSON document on stdout (and take ownership of it). */
void cli_print_json(json_t *doc);

/* Numbers on the command line are strict: the whole text, no blanks, finite (no nan or inf),
 * in range, every list element present ("5," is refused). Errors are one line in one style:
 * "OPTION wants <what> from LO to HI, not 'TEXT'". */

/* Parse "a,b,c" into at most max doubles; returns how many, or -1 when malformed. */
int cli_parse_doubles(const char *text, double *out, int max);
/* Parse a whole-string integer within [lo, hi]; returns 0 on success. */
int cli_parse_int(const char *text, long lo, long hi, long *out);
/* An option's whole number within [lo, hi] (VF_EINPUT "... wants a whole number from LO to HI"). */
vf_status cli_count(const char *option, const char *text, long lo, long hi, long *out);
/* The same into an int. */
vf_status cli_count_int(const char *option, const char *text, long lo, long hi, int *out);
/* An option's seed: any whole number from 0 to 2^64 - 1 (no sign, no overflow). */
vf_status cli_seed(const char *option, const char *text, uint64_t *out);
/* An option's number within [lo, hi] ("... wants a number from LO to HI"). */
vf_status cli_number(const char *option, const char *text, double lo, double hi, double *out);
/* An option's number within (lo, hi] ("... wants a number above LO and up to HI"). */
vf_status cli_number_above(const char *option, const char *text, double lo, double hi,
                           double *out);
/* An option's list of exactly n numbers; `what` names them ("fx,fy,cx,cy in pixels"). */
vf_status cli_numbers(const char *option, const char *text, int n, const char *what,
                      double *out);
/* An option's "WxH" (1..16384 each), or VF_EINPUT "OPTION wants WIDTHxHEIGHT ...". */
vf_status cli_size(const char *option, const char *text, int *width, int *height);

/* The classifiers an option names: "A,B,..." (names `vfcapture models` finds, or .onnx paths)
 * or "all" (every model found), both looked up in models_dir first when given (NULL: the
 * standard places). At most max; names resolved before any work, so a typo fails first. */
#define CLI_MAX_MODELS 40
vf_status cli_models(const char *option, const char *list, const char *models_dir,
                     char paths[][VF_PATH_MAX], int max, int *count);

/* Open the workspace at root (never created) and its trained field; on failure nothing stays
 * open. For the commands that only look at a field (render, eval, transfer). */
vf_status cli_open_trained(const char *root, vf_workspace *ws, vf_field **field);

/* Commands (one file each in pipeline/). */
int cmd_ingest(int argc, char **argv);
int cmd_classify(int argc, char **argv);
int cmd_info(int argc, char **argv);
int cmd_benchmark(int argc, char **argv);
int cmd_poses(int argc, char **argv);
int cmd_train(int argc, char **argv);
int cmd_render(int argc, char **argv);
int cmd_eval(int argc, char **argv);
int cmd_run(int argc, char **argv);
int cmd_calib(int argc, char **argv);
int cmd_attack(int argc, char **argv);
int cmd_transfer(int argc, char **argv);
int cmd_localize(int argc, char **argv);
int cmd_score(int argc, char **argv);
int cmd_export(int argc, char **argv);
int cmd_reshoot(int argc, char **argv);
int cmd_real(int argc, char **argv);
int cmd_models(int argc, char **argv);
int cmd_simulate(int argc, char **argv);
int cmd_study(int argc, char **argv);
int cmd_tables(int argc, char **argv);

#endif
