/* The localization map from COLMAP's database.db: the SIFT descriptor of every observation
 * in the sparse model's point tracks. The database holds one BLOB of rows x 128 uint8 per
 * image (table `descriptors`); a track entry (IMAGE_ID, POINT2D_IDX) is a row of it. */
#include <sqlite3.h>
#include <stdlib.h>
#include <string.h>

#include "localize_internal.h"
#include "vf/fsutil.h"

/* One image's descriptors, read into a malloc'd rows x 128 array. */
static vf_status read_descriptors(sqlite3_stmt *stmt, const char *database, int image_id,
                                  unsigned char **out, int *rows)
{
    *out = NULL;
    *rows = 0;
    sqlite3_reset(stmt);
    sqlite3_bind_int(stmt, 1, image_id);
    int rc = sqlite3_step(stmt);
    if (rc == SQLITE_DONE)
        return vf_fail(VF_EINPUT, "%s has no descriptors for image %d of the sparse model: "
                                  "the database and the model come from different runs",
                       database, image_id);
    if (rc != SQLITE_ROW)
        return vf_fail(VF_EINPUT, "cannot read %s: %s", database,
                       sqlite3_errmsg(sqlite3_db_handle(stmt)));
    int n = sqlite3_column_int(stmt, 0), cols = sqlite3_column_int(stmt, 1);
    const void *blob = sqlite3_column_blob(stmt, 2);
    int bytes = sqlite3_column_bytes(stmt, 2);
    if (cols != VF_DESC_DIM || n < 0 || (long long)n * cols != bytes || (n > 0 && !blob))
        return vf_fail(VF_EINPUT, "%s: descriptors of image %d are not %d-byte SIFT (%d x %d, "
                                  "%d bytes)",
                       database, image_id, VF_DESC_DIM, n, cols, bytes);
    *out = malloc((size_t)bytes + 1);
    if (!*out)
        return vf_fail(VF_EINTERNAL, "out of memory reading %s", database);
    memcpy(*out, blob, (size_t)bytes);
    *rows = n;
    return VF_OK;
}

/* Copy each track entry's descriptor into the map. */
static vf_status fill_map(const vf_colmap_model *model, unsigned char **per_image,
                          const int *rows, const char *database, vf_loc_map *map)
{
    size_t total = 0;
    for (int i = 0; i < model->point_count; i++)
        total += (size_t)model->points[i].track_length;
    map->descriptors = malloc(total * VF_DESC_DIM + 1);
    map->point = malloc((total + 1) * sizeof *map->point);
    if (!map->descriptors || !map->point)
        return vf_fail(VF_EINTERNAL, "out of memory for %zu descriptors", total);
    for (int i = 0; i < model->point_count; i++) {
        const vf_colmap_point *pt = &model->points[i];
        for (int k = 0; k < pt->track_length; k++) {
            int image = -1;
            for (int j = 0; j < model->image_count && image < 0; j++)
                if (model->images[j].id == pt->track[2 * k])
                    image = j;
            int row = pt->track[2 * k + 1];
            if (image < 0 || row < 0 || row >= rows[image])
                return vf_fail(VF_EINPUT, "%s does not match the sparse model (point %lld sees "
                                          "keypoint %d of image %d)",
                               database, pt->id, row, pt->track[2 * k]);
            memcpy(map->descriptors + (size_t)map->count * VF_DESC_DIM,
                   per_image[image] + (size_t)row * VF_DESC_DIM, VF_DESC_DIM);
            map->point[map->count++] = i;
        }
    }
    return VF_OK;
}

vf_status vf_loc_map_load(const char *database, const vf_colmap_model *model, vf_loc_map *out)
{
    memset(out, 0, sizeof *out);
    if (!vf_is_file(database))
        return vf_fail(VF_EINPUT, "%s does not exist: run 'vfcapture poses' first", database);
    sqlite3 *db = NULL;
    sqlite3_stmt *stmt = NULL;
    if (sqlite3_open_v2(database, &db, SQLITE_OPEN_READONLY, NULL) != SQLITE_OK ||
        sqlite3_prepare_v2(db, "SELECT rows, cols, data FROM descriptors WHERE image_id = ?", -1,
                           &stmt, NULL) != SQLITE_OK) {
        vf_status status = vf_fail(VF_EINPUT, "%s is not a COLMAP database: %s", database,
                                   db ? sqlite3_errmsg(db) : "cannot open");
        sqlite3_close(db);
        return status;
    }
    int n = model->image_count;
    unsigned char **per_image = calloc((size_t)n + 1, sizeof *per_image);
    int *rows = calloc((size_t)n + 1, sizeof *rows);
    vf_status status = per_image && rows ? VF_OK : vf_fail(VF_EINTERNAL, "out of memory");
    for (int i = 0; status == VF_OK && i < n; i++)
        status = read_descriptors(stmt, database, model->images[i].id, &per_image[i], &rows[i]);
    sqlite3_finalize(stmt);
    sqlite3_close(db);
    if (status == VF_OK)
        status = fill_map(model, per_image, rows, database, out);
    for (int i = 0; per_image && i < n; i++)
        free(per_image[i]);
    free(per_image);
    free(rows);
    if (status != VF_OK)
        vf_loc_map_free(out);
    return status;
}

void vf_loc_map_free(vf_loc_map *map)
{
    free(map->descriptors);
    free(map->point);
    memset(map, 0, sizeof *map);
}
