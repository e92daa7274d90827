#include "cli.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "vf/classifier.h"
#include "vf/log.h"

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

int cli_parse_doubles(const char *text, double *out, int max)
{
    int count = 0;
    const char *p = text;
    while (*p) {
        if (count == max)
            return -1;
        char *end;
        errno = 0;
        out[count] = strtod(p, &end);
        if (end == p || errno)
            return -1;
        count++;
        p = end;
        if (*p == ',')
            p++;
        else if (*p)
            return -1;
    }
    return count;
}

int cli_parse_int(const char *text, long lo, long hi, long *out)
{
    char *end;
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

vf_status cli_number(const char *option, const char *text, double lo, double hi, double *out)
{
    double value;
    if (cli_parse_doubles(text, &value, 1) != 1 || !(value >= lo && value <= hi))
        return vf_fail(VF_EINPUT, "%s wants a number from %g to %g, not '%s'", option, lo, hi,
                       text);
    *out = value;
    return VF_OK;
}

vf_status cli_size(const char *option, const char *text, int *width, int *height)
{
    char tail;
    int w, h;
    if (sscanf(text, "%dx%d%c", &w, &h, &tail) != 2 || w <= 0 || h <= 0 || w > 16384 ||
        h > 16384)
        return vf_fail(VF_EINPUT, "%s wants WIDTHxHEIGHT, e.g. 1280x720, not '%s'", option, text);
    *width = w, *height = h;
    return VF_OK;
}

vf_status cli_open_trained(const char *root, vf_workspace *ws, vf_field **field)
{
    vf_status s = vf_workspace_open(root, 0, ws);
    if (s == VF_OK && (s = vf_field_load_workspace(ws, field)) != VF_OK)
        vf_workspace_close(ws);
    return s;
}
