/* vfcapture tables: the paper's tables of a study's finished workspaces (vf/study.h). */
#include <stdio.h>

#include "cli.h"
#include "vf/study.h"

static const char usage[] =
    "usage: vfcapture tables STUDY [--json]\n"
    "\n"
    "Read the finished workspaces of a study (the folder its workflow writes: one workspace an\n"
    "object, see 'vfcapture study --help') and write the paper's tables to STUDY/tables/:\n"
    "Table 1 (space x method x classifier: R(p*(v)), R(v*), Real(v*), Real(p*(v)), natural\n"
    "accuracy, random search; mean over objects with a 95% interval), Table 2 (lambda and the\n"
    "std of each parameter), Table 3 (transfer), ImageNet-V accuracies, a row per object and\n"
    "attack, failed objects with their error, seconds per stage; as CSV, all together in\n"
    "tables.md beside the paper's numbers, and table1.png.\n"
    "\n"
    "options:\n" CLI_COMMON_HELP;

int cmd_tables(int argc, char **argv)
{
    static const struct option longopts[] = {CLI_COMMON_OPTIONS, {0, 0, 0, 0}};
    cli_flags flags = {0};
    int c;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT, longopts, NULL)) != -1)
        cli_common_option(c, &flags, "tables", usage);
    if (optind != argc - 1) {
        vf_fail(VF_EINPUT, "give one study folder (see 'vfcapture tables --help')");
        return cli_fail("tables", VF_EINPUT);
    }
    json_t *doc = NULL;
    vf_status s = vf_study_tables(argv[optind], &doc);
    if (s != VF_OK)
        return cli_fail("tables", s);
    if (flags.json) {
        cli_print_json(doc);
        return 0;
    }
    printf("%lld objects, %lld attacks; tables in %s/ (tables.md, *.csv, table1.png)\n",
           json_integer_value(json_object_get(doc, "objects")),
           json_integer_value(json_object_get(doc, "attacks")),
           json_string_value(json_object_get(doc, "tables")));
    size_t i;
    json_t *f;
    json_array_foreach(json_object_get(doc, "failed"), i, f)
        printf("  %s (%s): %s\n", json_string_value(json_object_get(f, "object")),
               json_string_value(json_object_get(f, "stage")),
               json_string_value(json_object_get(f, "error")));
    json_decref(doc);
    return 0;
}
