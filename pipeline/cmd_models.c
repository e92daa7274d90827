/* vfcapture models: the classifiers a user can name, where they were found, and whether the
 * engine loads them. */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "vf/classifier.h"
#include "vf/fsutil.h"
#include "vf/log.h"
#include "vf/resources.h"

#define MAX_MODELS 256

static const char usage[] =
    "usage: vfcapture models [--models-dir DIR] [--engine E] [--json]\n"
    "\n"
    "List the ONNX classifiers found by name, in the order names are looked up:\n"
    "--models-dir, $VF_MODELS_DIR, the per-user folder ($XDG_DATA_HOME/vfcapture/models or\n"
    "~/.local/share/vfcapture/models) and the shared models folder. Each one is loaded with\n"
    "the engine to show its input size, or the reason it cannot be used.\n"
    "\n"
    "options:\n"
    "      --models-dir DIR   look here first\n" CLI_ENGINE_HELP CLI_COMMON_HELP;

enum { OPT_MODELS_DIR = CLI_OPT_FIRST_CUSTOM };

int cmd_models(int argc, char **argv)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        CLI_ENGINE_OPTION,
        {"models-dir", required_argument, NULL, OPT_MODELS_DIR},
        {0, 0, 0, 0},
    };
    cli_flags flags = {0};
    const char *models_dir = NULL;
    int c;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT, longopts, NULL)) != -1)
        if (!cli_common_option(c, &flags, "models", usage) && c == OPT_MODELS_DIR)
            models_dir = optarg;
    if (optind < argc) {
        fprintf(stderr, "vfcapture models: unexpected argument '%s'\n", argv[optind]);
        return VF_EINPUT;
    }
    if (models_dir && !vf_is_dir(models_dir))
        return cli_fail("models", vf_fail(VF_EINPUT, "--models-dir %s is not a folder", models_dir));

    char dirs[4][VF_PATH_MAX];
    int ndirs = vf_model_dirs(models_dir, dirs, 4);
    static char paths[MAX_MODELS][VF_PATH_MAX];
    int count = vf_model_list(models_dir, paths, MAX_MODELS);
    if (count > MAX_MODELS) {
        vf_warn("%d models found; listing the first %d", count, MAX_MODELS);
        count = MAX_MODELS;
    }
    json_t *list = json_array(), *searched = json_array();
    for (int i = 0; i < ndirs; i++) {
        json_array_append_new(searched, json_string(dirs[i]));
        if (!flags.json)
            printf("%s %s%s\n", i ? "        " : "folders", dirs[i], vf_is_dir(dirs[i]) ? "" : " (none)");
    }
    if (!flags.json)
        printf("\n%-34s %5s  %-18s %s\n", "name", "input", "engine", "file");
    for (int m = 0; m < count; m++) {
        char name[256];
        vf_path_basename(name, sizeof name, paths[m], 1);
        vf_classifier *cls;
        vf_status s = vf_classifier_open(paths[m], &cls);
        json_t *row = json_pack("{s:s, s:s}", "name", name, "path", paths[m]);
        if (s == VF_OK) {
            json_object_set_new(row, "input_size", json_integer(vf_classifier_input_size(cls)));
            json_object_set_new(row, "engine", json_string(vf_classifier_engine(cls)));
            if (!flags.json)
                printf("%-34s %5d  %-18s %s\n", name, vf_classifier_input_size(cls),
                       vf_classifier_engine(cls), paths[m]);
            vf_classifier_close(cls);
        } else {
            json_object_set_new(row, "error", json_string(vf_error_message()));
            if (!flags.json)
                printf("%-34s %5s  %-18s %s\n%34s   cannot be used: %s\n", name, "-", "-",
                       paths[m], "", vf_error_message());
        }
        json_array_append_new(list, row);
    }
    if (flags.json)
        cli_print_json(json_pack("{s:o, s:o}", "folders", searched, "models", list));
    else {
        json_decref(list);
        json_decref(searched);
        if (count == 0)
            printf("(no .onnx files)\n");
    }
    return VF_OK;
}
