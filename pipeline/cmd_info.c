/* vfcapture info: what a workspace holds, stage by stage. */
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "vf/workspace.h"

static const char usage[] =
    "usage: vfcapture info WS [--json]\n"
    "\n"
    "Show which stages have run in the workspace WS, when, with which parameters, and what\n"
    "they reported; a stage built on one rerun since is marked STALE.\n"
    "\n"
    "options:\n" CLI_COMMON_HELP;

/* A manifest's string, or "?" when a hand-edited or foreign manifest lacks it. */
static const char *text_or(const json_t *x)
{
    return json_is_string(x) ? json_string_value(x) : "?";
}

int cmd_info(int argc, char **argv)
{
    static const struct option longopts[] = {CLI_COMMON_OPTIONS, {0, 0, 0, 0}};
    cli_flags flags = {0};
    int c;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT, longopts, NULL)) != -1)
        cli_common_option(c, &flags, "info", usage);
    if (optind != argc - 1) {
        vf_fail(VF_EINPUT, "give one workspace folder (see 'vfcapture info --help')");
        return cli_fail("info", VF_EINPUT);
    }
    vf_workspace ws;
    vf_status status = vf_workspace_open(argv[optind], 0, &ws);
    if (status != VF_OK)
        return cli_fail("info", status);
    if (flags.json) {
        cli_print_json(json_incref(ws.manifest));
    } else {
        printf("workspace %s (created by vfcapture %s)\n", ws.root,
               text_or(json_object_get(ws.manifest, "version")));
        const char *name;
        json_t *record;
        json_object_foreach(json_object_get(ws.manifest, "stages"), name, record)
        {
            char *summary = json_dumps(json_object_get(record, "summary"), JSON_COMPACT);
            char why[256], stale[300] = "";
            if (vf_workspace_is_stale(&ws, name, why, sizeof why))
                snprintf(stale, sizeof stale, "  STALE: %s", why);
            printf("  %-8s done %s in %.1f s%s  %s\n", name,
                   text_or(json_object_get(record, "completed")),
                   json_number_value(json_object_get(record, "seconds")), stale,
                   summary ? summary : "");
            free(summary);
        }
    }
    vf_workspace_close(&ws);
    return 0;
}
