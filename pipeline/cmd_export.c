/* vfcapture export: parse the options, run the export stage (vf/export.h), list the targets. */
#include <stdio.h>
#include <stdlib.h>

#include "cli.h"
#include "vf/export.h"

static const char usage[] =
    "usage: vfcapture export WS [--count M] [--attack NAME]\n"
    "\n"
    "Turn an attack's result (WS/attack/NAME/attack.json) into target shots: v* and M samples of\n"
    "p*(v) spread over the distribution. For each: camera-to-world in the object frame and in\n"
    "COLMAP's frame (when WS has poses), and in words (azimuth and elevation around the object\n"
    "centre, distance, height, roll, the point looked at; metres when WS/calib/scale.json gives\n"
    "the scale), the predicted class, and a preview rendered from WS/train/model.vff when it\n"
    "exists.\n"
    "Writes WS/export/targets.json, targets.csv, previews/ and shot_card.png.\n"
    "\n"
    "options:\n"
    "      --count M          samples of p*(v) besides v* (default 8)\n" CLI_ATTACK_HELP
        CLI_ENGINE_HELP CLI_COMMON_HELP;

static vf_status parse(int argc, char **argv, const char **ws, vf_export_options *o,
                       cli_flags *flags)
{
    static const struct option longopts[] = {CLI_COMMON_OPTIONS,
                                             CLI_ENGINE_OPTION,
                                             CLI_ATTACK_OPTION,
                                             {"count", required_argument, NULL, CLI_OPT_FIRST_CUSTOM},
                                             {0, 0, 0, 0}};
    int c;
    long n;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT "n:", longopts, NULL)) != -1) {
        if (cli_common_option(c, flags, "export", usage))
            continue;
        if (c == CLI_OPT_ATTACK)
            o->attack = optarg;
        if (c == 'n')
            cli_deprecated("export", "-n", "--count");
        if (c == 'n' || c == CLI_OPT_FIRST_CUSTOM) {
            if (cli_count("--count", optarg, 0, VF_EXPORT_MAX_COUNT, &n) != VF_OK)
                return VF_EINPUT;
            o->count = (int)n;
        }
    }
    if (optind != argc - 1)
        return vf_fail(VF_EINPUT, "give one workspace folder (see 'vfcapture export --help')");
    *ws = argv[optind];
    return VF_OK;
}

static double number(const json_t *o, const char *key)
{
    return json_number_value(json_object_get(o, key));
}

/* "1.20 m" when the export knows the scale, else "3.10 units". */
static void distance_text(const json_t *words, const char *key, char *out, size_t size)
{
    char metres[32];
    snprintf(metres, sizeof metres, "%s_m", key);
    if (json_object_get(words, metres))
        snprintf(out, size, "%.2f m", number(words, metres));
    else
        snprintf(out, size, "%.2f units", number(words, key));
}

static void print_targets(const char *ws, const json_t *doc)
{
    size_t i;
    const json_t *t;
    json_array_foreach(json_object_get(doc, "targets"), i, t)
    {
        const json_t *w = json_object_get(t, "words");
        const char *predicted =
            json_string_value(json_object_get(json_object_get(t, "prediction"), "name"));
        const json_t *trust = json_object_get(t, "trust");
        char d[32], h[32], gap[64] = "";
        distance_text(w, "distance", d, sizeof d);
        distance_text(w, "height", h, sizeof h);
        if (trust)
            snprintf(gap, sizeof gap, "; %.0f deg from the nearest photo%s",
                     number(trust, "gap_deg"),
                     json_is_true(json_object_get(trust, "trusted")) ? "" : " (BEYOND the limit)");
        printf("target %zu (%s): azimuth %.0f deg, elevation %.0f deg, distance %s, height %s, "
               "roll %.0f deg%s%s%s\n",
               i, json_string_value(json_object_get(t, "kind")), number(w, "azimuth_deg"),
               number(w, "elevation_deg"), d, h, number(w, "roll_deg"),
               predicted ? "; predicted " : "", predicted ? predicted : "", gap);
    }
    printf("targets in %s/export/ (targets.json, targets.csv, shot_card.png)\n", ws);
}

int cmd_export(int argc, char **argv)
{
    const char *root = NULL;
    vf_export_options o;
    vf_export_defaults(&o);
    cli_flags flags = {0};
    vf_workspace ws;
    json_t *doc = NULL;
    vf_status s = parse(argc, argv, &root, &o, &flags);
    if (s == VF_OK && (s = vf_workspace_open(root, 0, &ws)) == VF_OK) {
        s = vf_export_run(&ws, &o, &doc);
        vf_workspace_close(&ws);
    }
    if (s != VF_OK)
        return cli_fail("export", s);
    if (flags.json)
        cli_print_json(doc);
    else {
        print_targets(root, doc);
        json_decref(doc);
    }
    return 0;
}
