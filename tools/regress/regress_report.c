/* regress_report.c — sightline-regress's JUnit XML and HTML reports: see regress.h. Single-threaded. */
#include "regress.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

/* Writes s with XML/HTML special characters escaped. */
static void escaped(FILE *f, const char *s)
{
    for (; *s; s++) {
        switch (*s) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        case '\'': fputs("&apos;", f); break;
        default:
            if ((unsigned char)*s >= 0x20 || *s == '\t' || *s == '\n')
                fputc(*s, f);
        }
    }
}

static sl_status close_checked(FILE *f, const char *path, sl_err *err)
{
    int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        return sl_err_set(err, SL_ERR_IO, "%s: write failed: %s", path, strerror(errno));
    return SL_OK;
}

sl_status regress_write_junit(const regress_suite *s, const regress_result *r, double seconds, const char *path,
                              sl_err *err)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return sl_err_set(err, SL_ERR_IO, "%s: cannot create: %s", path, strerror(errno));
    int failures = 0, errors = 0;
    for (int i = 0; i < s->count; i++) {
        failures += r[i].outcome == REGRESS_FAIL;
        errors += r[i].outcome == REGRESS_ERROR;
    }
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites>\n<testsuite name=\"");
    escaped(f, s->name);
    fprintf(f, "\" tests=\"%d\" failures=\"%d\" errors=\"%d\" time=\"%.3f\">\n", s->count, failures, errors, seconds);
    for (int i = 0; i < s->count; i++) {
        fprintf(f, "  <testcase classname=\"");
        escaped(f, s->name);
        fprintf(f, "\" name=\"");
        escaped(f, s->cases[i].name);
        fprintf(f, "\" time=\"%.3f\"", r[i].seconds);
        if (r[i].outcome != REGRESS_FAIL && r[i].outcome != REGRESS_ERROR) {
            fprintf(f, "/>\n");
            continue;
        }
        const char *tag = r[i].outcome == REGRESS_FAIL ? "failure" : "error";
        fprintf(f, ">\n    <%s message=\"", tag);
        escaped(f, r[i].message);
        fprintf(f, "\">");
        escaped(f, r[i].message);
        fprintf(f, "</%s>\n  </testcase>\n", tag);
    }
    fprintf(f, "</testsuite>\n</testsuites>\n");
    return close_checked(f, path, err);
}

static const char *outcome_name(regress_outcome o)
{
    switch (o) {
    case REGRESS_PASS: return "pass";
    case REGRESS_FAIL: return "FAIL";
    case REGRESS_ERROR: return "ERROR";
    case REGRESS_UPDATED: return "updated";
    case REGRESS_UNCHANGED: return "unchanged";
    }
    return "?";
}

sl_status regress_write_html(const regress_suite *s, const regress_result *r, const char *out_dir, sl_err *err)
{
    char path[REGRESS_PATH_MAX + 32];
    snprintf(path, sizeof path, "%s/index.html", out_dir);
    FILE *f = fopen(path, "w");
    if (!f)
        return sl_err_set(err, SL_ERR_IO, "%s: cannot create: %s", path, strerror(errno));
    fprintf(f, "<!doctype html>\n<meta charset=\"utf-8\">\n<title>sightline-regress: ");
    escaped(f, s->name);
    fprintf(f, "</title>\n<style>body{font:14px sans-serif;background:#222;color:#ddd}td{padding:4px 8px;"
               "vertical-align:top}.FAIL,.ERROR{color:#f66}img{image-rendering:pixelated;width:256px}</style>\n");
    fprintf(f, "<h1>suite ");
    escaped(f, s->name);
    fprintf(f, "</h1>\n<p>golden (a copy from ");
    escaped(f, s->dir);
    fprintf(f, "/golden), new render, heat map of |difference|: failures only, for a path its worst frame</p>\n"
               "<table>\n");
    for (int i = 0; i < s->count; i++) {
        const regress_case *c = &s->cases[i];
        fprintf(f, "<tr><td class=\"%s\">%s</td><td>", outcome_name(r[i].outcome), outcome_name(r[i].outcome));
        escaped(f, c->name);
        fprintf(f, "<br>");
        escaped(f, r[i].message);
        fprintf(f, "</td>");
        if (r[i].outcome == REGRESS_FAIL) {
            char frame[64] = "";
            if (c->is_path)
                snprintf(frame, sizeof frame, "/%05d", r[i].worst_frame);
            fprintf(f, "<td><img src=\"golden/");
            escaped(f, c->name);
            fprintf(f, ".png\"></td><td><img src=\"new/");
            escaped(f, c->name);
            fprintf(f, "%s.png\"></td><td><img src=\"heat/", frame);
            escaped(f, c->name);
            fprintf(f, ".png\"></td>");
        }
        fprintf(f, "</tr>\n");
    }
    fprintf(f, "</table>\n");
    return close_checked(f, path, err);
}
