/* vf/json.h: reading and writing the workspace's JSON files (jansson documents).
 *
 * Files are saved atomically (a temporary name, then rename), indented, keys in insertion
 * order, numbers with 17 significant digits so that every double reads back bit for bit (a
 * resumed stage compares saved numbers with recomputed ones). Viewpoints, vectors and poses
 * are arrays of numbers; a 4x4 pose is four rows of four.
 *
 * Memory: documents are jansson references; functions named "new reference" hand one to the
 * caller, who releases it with json_decref. */
#ifndef VF_JSON_H
#define VF_JSON_H

#include <jansson.h>

#include "vf/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Save a JSON document atomically. */
vf_status vf_json_save(const char *path, const json_t *doc);
/* Load a JSON document; errors name the file and the line. */
vf_status vf_json_load(const char *path, json_t **out);
/* A number (a new reference); inf and nan as null. JSON has no inf or nan, and jansson's
 * json_real gives NULL for them, which makes a whole json_pack document NULL: so every double
 * the project writes goes through here (in json_pack as "o" with vf_json_number(x), never "f").
 * Readers take null as "not measured". */
json_t *vf_json_number(double x);
/* n numbers as a JSON array (a new reference); inf and nan as null. */
json_t *vf_json_doubles(const double *x, int n);
/* A 4x4 row-major matrix as four rows of four numbers (a new reference). */
json_t *vf_json_mat4(const double m[16]);
/* An array of exactly n finite numbers into out: 1, else 0 (out partly written). */
int vf_json_read_doubles(const json_t *array, double *out, int n);

#ifdef __cplusplus
}
#endif
#endif
