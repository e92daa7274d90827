/* The names of the surroundings modes (vf/field.h): what the trainer, its checkpoints and the
 * train stage's report and command line call them. */
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
