/* The names of the trainer's modes (vf/field.h: surroundings, colour model): what the trainer,
 * its checkpoints and the train stage's report and command line call them. */
#include <string.h>

#include "vf/field.h"

static const char *const surroundings_names[] = {"auto", "grid", "none"};
static const char *const color_names[] = {"view", "diffuse"};

static const char *name_of(const char *const *names, int count, int value)
{
    return value >= 0 && value < count ? names[value] : "?";
}

static int parse_name(const char *const *names, int count, const char *name)
{
    for (int i = 0; i < count; i++)
        if (!strcmp(name, names[i]))
            return i;
    return -1;
}

const char *vf_field_surroundings_name(vf_field_surroundings s)
{
    return name_of(surroundings_names, 3, (int)s);
}

int vf_field_surroundings_parse(const char *name)
{
    return parse_name(surroundings_names, 3, name);
}

const char *vf_field_color_name(vf_field_color c)
{
    return name_of(color_names, 2, (int)c);
}

int vf_field_color_parse(const char *name)
{
    return parse_name(color_names, 2, name);
}
