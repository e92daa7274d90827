#include "cli.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "vf/classifier.h"
#include "vf/log.h"
#include "vf/resources.h"

int cli_common_option(int opt, cli_flags *flags, const char *command, const char *usage)
{
    switch (opt) {
    case 'h':
        fputs(usage, stdout);
        exit(0);
    case 'q':
        flags->quiet = 1;
        vf_log_set_quiet(1);
        return 1;
    case CLI_OPT_JSON:
        flags->json = 1;
        return 1;
    case CLI_OPT_ENGINE: {
        vf_engine engine;
        if (vf_engine_parse(optarg, &engine) != VF_OK)
            exit(cli_fail(command, VF_EINPUT));
        vf_classifier_set_engine(engine);
        return 1;
    }
    case '?':
    case ':':
        fprintf(stderr, "vfcapture %s: see 'vfcapture %s --help'\n", command, command);
        exit(VF_EINPUT);
    default:
        return 0;
    }
}

void cli_deprecated(const char *command, const char *old, const char *now)
{
    fprintf(stderr, "vfcapture %s: %s is deprecated: use %s\n", command, old, now);
}

int cli_fail(const char *command, vf_status status)
{
    const char *message = vf_error_message();
    fprintf(stderr, "vfcapture %s: error: %s\n", command, message[0] ? message : "failed");
    return (int)status;
}

void cli_print_json(json_t *doc)
{
    char *text = json_dumps(doc, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10));
    if (text) {
        puts(text);
        free(text);
    }
    fflush(stdout);
    json_decref(doc);
}

/* Numbers are strict everywhere: the whole text, no blanks, finite, no empty list element;
 * strtod and strtol alone take " 5", "nan", "inf" and "5," (and sscanf %d overflows). */
int cli_parse_doubles(const char *text, double *out, int max)
{
    int count = 0;
    const char *p = text;
    if (!*p)
        return -1;
    for (;;) {
        char *end;
        if (count == max || isspace((unsigned char)*p))
            return -1;
        errno = 0;
        double x = strtod(p, &end);
        if (end == p || errno || !isfinite(x))
            return -1;
        out[count++] = x;
        p = end;
        if (!*p)
            return count;
        if (*p++ != ',')
            return -1;
    }
}

int cli_parse_int(const char *text, long lo, long hi, long *out)
{
    char *end;
    if (!*text || isspace((unsigned char)*text))
        return -1;
    errno = 0;
    long value = strtol(text, &end, 10);
    if (end == text || *end || errno || value < lo || value > hi)
        return -1;
    *out = value;
    return 0;
}

vf_status cli_count(const char *option, const char *text, long lo, long hi, long *out)
{
    if (cli_parse_int(text, lo, hi, out))
        return vf_fail(VF_EINPUT, "%s wants a whole number from %ld to %ld, not '%s'", option, lo,
                       hi, text);
    return VF_OK;
}

vf_status cli_count_int(const char *option, const char *text, long lo, long hi, int *out)
{
    long n = 0;
    vf_status status = cli_count(option, text, lo, hi, &n);
    if (status == VF_OK)
        *out = (int)n;
    return status;
}

vf_status cli_seed(const char *option, const char *text, uint64_t *out)
{
    char *end;
    errno = 0;
    unsigned long long value = isdigit((unsigned char)text[0]) ? strtoull(text, &end, 10) : 0;
    if (!isdigit((unsigned char)text[0]) || *end || errno)
        return vf_fail(VF_EINPUT, "%s wants a whole number from 0 to %llu, not '%s'", option,
                       (unsigned long long)UINT64_MAX, text);
    *out = (uint64_t)value;
    return VF_OK;
}

vf_status cli_number(const char *option, const char *text, double lo, double hi, double *out)
{
    double value;
    if (cli_parse_doubles(text, &value, 1) != 1 || !(value >= lo && value <= hi))
        return vf_fail(VF_EINPUT, "%s wants a number from %g to %g, not '%s'", option, lo, hi,
                       text);
    *out = value;
    return VF_OK;
}

vf_status cli_number_above(const char *option, const char *text, double lo, double hi,
                           double *out)
{
    double value;
    if (cli_parse_doubles(text, &value, 1) != 1 || !(value > lo && value <= hi))
        return vf_fail(VF_EINPUT, "%s wants a number above %g and up to %g, not '%s'", option,
                       lo, hi, text);
    *out = value;
    return VF_OK;
}

vf_status cli_numbers(const char *option, const char *text, int n, const char *what,
                      double *out)
{
    if (cli_parse_doubles(text, out, n) != n)
        return vf_fail(VF_EINPUT, "%s wants %d comma-separated numbers (%s), not '%s'", option,
                       n, what, text);
    return VF_OK;
}

vf_status cli_size(const char *option, const char *text, int *width, int *height)
{
    const char *x = strchr(text, 'x');
    long w = 0, h = 0;
    char first[24];
    if (x && (size_t)(x - text) < sizeof first) {
        memcpy(first, text, (size_t)(x - text));
        first[x - text] = 0;
    }
    if (!x || (size_t)(x - text) >= sizeof first || cli_parse_int(first, 1, 16384, &w) ||
        cli_parse_int(x + 1, 1, 16384, &h))
        return vf_fail(VF_EINPUT, "%s wants WIDTHxHEIGHT from 1x1 to 16384x16384, e.g. 1280x720, "
                       "not '%s'", option, text);
    *width = (int)w, *height = (int)h;
    return VF_OK;
}

vf_status cli_models(const char *option, const char *list, const char *models_dir,
                     char paths[][VF_PATH_MAX], int max, int *count)
{
    *count = 0;
    if (!strcmp(list, "all")) {
        *count = vf_model_list(models_dir, paths, max);
        return *count > 0 ? VF_OK
                          : vf_fail(VF_EINPUT, "%s all: no model found (see 'vfcapture models')",
                                    option);
    }
    char buf[4096];
    if (snprintf(buf, sizeof buf, "%s", list) >= (int)sizeof buf)
        return vf_fail(VF_EINPUT, "%s is too long", option);
    char *save = NULL;
    for (char *name = strtok_r(buf, ",", &save); name; name = strtok_r(NULL, ",", &save)) {
        if (*count == max)
            return vf_fail(VF_EINPUT, "%s: at most %d models at a time", option, max);
        vf_status s = vf_find_model(name, models_dir, paths[*count], VF_PATH_MAX);
        if (s != VF_OK)
            return s;
        (*count)++;
    }
    return *count ? VF_OK : vf_fail(VF_EINPUT, "%s names no model", option);
}

vf_status cli_open_trained(const char *root, vf_workspace *ws, vf_field **field)
{
    vf_status s = vf_workspace_open(root, 0, ws);
    if (s == VF_OK && (s = vf_field_load_workspace(ws, field)) != VF_OK)
        vf_workspace_close(ws);
    return s;
}
