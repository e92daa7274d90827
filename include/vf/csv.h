/* vf/csv.h: the one writer of CSV fields (RFC 4180), for every table the project writes
 * (export's targets.csv, score's frames.csv and summary, the benchmark's and the study's
 * tables).
 *
 * Text is quoted only when it holds a comma, a quote or a line break, and a quote inside is
 * doubled: a class name such as `"crt screen"` or a folder with a comma cannot shift the
 * columns. Numbers are written by the caller with printf (never quoted). */
#ifndef VF_CSV_H
#define VF_CSV_H

#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Write `text` as one CSV field (NULL as an empty field), quoted when it must be. */
void vf_csv_text(FILE *f, const char *text);
/* The same after a separator: ",text". */
void vf_csv_next(FILE *f, const char *text);

#ifdef __cplusplus
}
#endif
#endif
