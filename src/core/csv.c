#include "vf/csv.h"

#include <string.h>

void vf_csv_text(FILE *f, const char *text)
{
    if (!text)
        return;
    if (!strpbrk(text, ",\"\r\n")) {
        fputs(text, f);
        return;
    }
    fputc('"', f);
    for (const char *c = text; *c; c++) {
        if (*c == '"')
            fputc('"', f);
        fputc(*c, f);
    }
    fputc('"', f);
}

void vf_csv_next(FILE *f, const char *text)
{
    fputc(',', f);
    vf_csv_text(f, text);
}
