/* src/physical/shot_card.h: the export's shot card, one PNG a person takes to the object: a tile
 * per target with its preview render, the nearest photo beside it, and the numbers to act on. Drawn
 * with cairo. Internal to the export stage; inputs are borrowed. */
#ifndef VF_PHYSICAL_SHOT_CARD_H
#define VF_PHYSICAL_SHOT_CARD_H

#include "vf/error.h"
#include "vf/image.h"

#define SHOT_CARD_LINES 6

typedef struct shot_tile {
    const vf_image *preview;            /* RGB 0..1, any size, or NULL (no trained field) */
    const vf_image *photo;              /* the nearest training photo, or NULL */
    char title[96];                     /* "target 0: v*" */
    char lines[SHOT_CARD_LINES][128];   /* the numbers, one per line ("" ends early) */
} shot_tile;

/* Draw `count` tiles in a grid (4 per row) under a heading and save to path (PNG). */
vf_status vf__shot_card_save(const char *path, const char *heading, const shot_tile *tiles,
                             int count);

#endif
