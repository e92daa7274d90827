/* The small writers every stage shares: vf/csv.h (RFC 4180 fields: names with commas, quotes
 * or line breaks cannot shift a table's columns; the old writers quoted names without doubling
 * their quotes, and the study's wrote a comma-holding name unquoted in one place) and
 * vf/json.h's vf_json_number (nan and inf as null, so one bad number never drops a whole
 * document: jansson's json_pack with "f" returns NULL on a NaN), and vf/camera.h's JSON. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "vf/camera.h"
#include "vf/csv.h"
#include "vf/json.h"

static void test_csv(void)
{
    char *text = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&text, &size);
    vf_csv_text(f, "plain");
    vf_csv_next(f, "a, b");
    vf_csv_next(f, "say \"hi\"");
    vf_csv_next(f, "two\nlines");
    vf_csv_next(f, NULL);
    vf_csv_next(f, "");
    fclose(f);
    const char *want = "plain,\"a, b\",\"say \"\"hi\"\"\",\"two\nlines\",,";
    CHECK(text && !strcmp(text, want), "fields quoted only when needed, quotes doubled: [%s]",
          text ? text : "");
    free(text);
}

static void test_json_number(void)
{
    json_t *doc = json_pack("{s:o, s:o, s:o, s:o}", "a", vf_json_number(0.25), "nan",
                            vf_json_number(NAN), "inf", vf_json_number(-INFINITY), "b",
                            vf_json_number(1e300));
    CHECK(doc != NULL, "a document with nan and inf is still made");
    CHECK(json_real_value(json_object_get(doc, "a")) == 0.25 &&
              json_real_value(json_object_get(doc, "b")) == 1e300,
          "finite numbers kept");
    CHECK(json_is_null(json_object_get(doc, "nan")) && json_is_null(json_object_get(doc, "inf")),
          "nan and inf written as null");
    json_t *old = json_pack("{s:f}", "nan", NAN);
    CHECK(old == NULL, "jansson's own \"f\" drops the document (why the helper exists)");
    json_decref(old);
    json_decref(doc);
}

/* One camera format: what vf_camera_json writes, vf_camera_from_json reads back, distortion
 * included (attack.json used to drop k1..p2), and one set of bounds for every reader. */
static void test_camera_json(void)
{
    vf_camera c = {.width = 1440, .height = 1920, .fx = 1500.5, .fy = 1499.25, .cx = 720.1,
                   .cy = 961.3, .k1 = -0.12, .k2 = 0.03, .p1 = 1e-4, .p2 = -2e-4};
    json_t *doc = vf_camera_json(&c);
    vf_camera back = {0};
    CHECK(vf_camera_from_json(doc, "test", &back) == VF_OK && !memcmp(&back, &c, sizeof c),
          "the camera round-trips bit for bit, distortion included: %s", vf_error_message());
    json_object_set_new(doc, "w", json_real(1e300));
    CHECK(vf_camera_from_json(doc, "test", &back) == VF_EINPUT && strstr(vf_error_message(), "w"),
          "a huge width is refused before any cast: %s", vf_error_message());
    json_object_set_new(doc, "w", json_integer(VF_CAMERA_MAX_SIDE + 1));
    CHECK(vf_camera_from_json(doc, "test", &back) == VF_EINPUT, "a width over the bound refused");
    json_object_set_new(doc, "w", json_integer(1440));
    json_object_del(doc, "cy");
    CHECK(vf_camera_from_json(doc, "test", &back) == VF_EINPUT && strstr(vf_error_message(), "cy"),
          "a missing key is named: %s", vf_error_message());
    json_decref(doc);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_csv);
    CHECK_CASE(test_json_number);
    CHECK_CASE(test_camera_json);
    return check_finish();
}
