/* The names of the trainer's modes (vf/field.h: surroundings, colour model): what the trainer,
 * its checkpoints and the train stage's report and command line call them. */
#include <string.h>

#include "vf/field.h"

static const char *const surroundings_names[] = {"auto", "grid", "none"};

const char *vf_field_surroundings_name(vf_field_surroundings s)
{
    return (unsigned)s < 3 ? surroundings_names[s] : "?";
}

int vf_field_surroundings_parse(const char *name)
{
    for (int i = 0; i < 3; i++)
        if (!strcmp(name, surroundings_names[i]))
            return i;
    return -1;
}

static const char *const color_names[] = {"view", "diffuse"};

const char *vf_field_color_name(vf_field_color c)
{
    return (unsigned)c < 2 ? color_names[c] : "?";
}

int vf_field_color_parse(const char *name)
{
    for (int i = 0; i < 2; i++)
        if (!strcmp(name, color_names[i]))
            return i;
    return -1;
}
