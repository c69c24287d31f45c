/* lr_write.c — the SINTEF LRsplines text writer (see sl_lr_write.h).
 *
 * Layout, as LR::LRSplineVolume::write, Basisfunction::write,
 * MeshRectangle::write and Element::write of the reference library print it:
 *   # LRSPLINE VOLUME
 *   #<TAB>p1<TAB>p2<TAB>p3<TAB>Nbasis<TAB>Nline<TAB>Nel<TAB>dim<TAB>rat
 *   <TAB>order_u<TAB>order_v<TAB>order_w<TAB>nb<TAB>nm<TAB>ne<TAB>dim<TAB>0
 *   # Basis functions:
 *   id: [u0 u1 .. ] x [v0 .. ] x [w0 .. ] c0 c1 .. (gamma)
 *   # Mesh rectangles:
 *   [u0, u1] x [v0, v1] x [w0, w1] (multiplicity)
 *   # Elements:
 *   id [3] : (umin, vmin, wmin) x (umax, vmax, wmax)    {b0, b1, ..}
 * (p1..p3 are orders, degree + 1, as in the reference.) Numbers are %.17g,
 * one more digit than the reference, so values survive a round trip.
 * Any thread; no GL. The output goes through one small formatting buffer. */
#include "sl_lr_write.h"

#include <stdarg.h>
#include <string.h>
#include <zlib.h>

typedef struct writer {
    FILE *f;     /* or */
    gzFile gz;
    int failed;
} writer;

static void emit(writer *w, const char *fmt, ...)
{
    char buf[256];
    if (w->failed)
        return;
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= sizeof buf) {
        w->failed = 1;
        return;
    }
    if (w->gz) {
        if (n > 0 && gzwrite(w->gz, buf, (unsigned)n) != n)
            w->failed = 1;
    } else if (fwrite(buf, 1, (size_t)n, w->f) != (size_t)n) {
        w->failed = 1;
    }
}

static void write_all(const sl_lr_volume *lr, writer *w)
{
    emit(w, "# LRSPLINE VOLUME\n");
    emit(w, "#\tp1\tp2\tp3\tNbasis\tNline\tNel\tdim\trat\n\t");
    emit(w, "%d\t%d\t%d\t%zu\t%zu\t%zu\t%d\t%d\n", lr->order[0], lr->order[1], lr->order[2],
         lr->basis_count, lr->meshrect_count, lr->element_count, lr->dim, 0);
    emit(w, "# Basis functions:\n");
    for (size_t i = 0; i < lr->basis_count && !w->failed; i++) {
        const sl_lr_basis *b = &lr->basis[i];
        emit(w, "%zu: ", i);
        for (int d = 0; d < 3; d++) {
            if (d > 0)
                emit(w, "x ");
            emit(w, "[");
            for (int k = 0; k <= lr->order[d]; k++)
                emit(w, "%.17g ", b->knots[d][k]);
            emit(w, "] ");
        }
        for (int c = 0; c < lr->dim; c++)
            emit(w, "%.17g ", b->coef[c]);
        emit(w, "(%.17g)\n", b->gamma);
    }
    emit(w, "# Mesh rectangles:\n");
    for (size_t i = 0; i < lr->meshrect_count && !w->failed; i++) {
        const sl_lr_meshrect *m = &lr->meshrects[i];
        emit(w, "[%.17g, %.17g] x [%.17g, %.17g] x ", m->lo[0], m->hi[0], m->lo[1], m->hi[1]);
        emit(w, "[%.17g, %.17g] (%d)\n", m->lo[2], m->hi[2], m->multiplicity);
    }
    emit(w, "# Elements:\n");
    for (size_t i = 0; i < lr->element_count && !w->failed; i++) {
        const sl_lr_element *e = &lr->elements[i];
        emit(w, "%zu [3] : (%.17g, %.17g, %.17g) x ", i, e->lo[0], e->lo[1], e->lo[2]);
        emit(w, "(%.17g, %.17g, %.17g)    {", e->hi[0], e->hi[1], e->hi[2]);
        for (uint32_t k = 0; k < e->basis_count; k++)
            emit(w, k ? ", %u" : "%u", lr->element_basis[e->basis_offset + k]);
        emit(w, "}\n");
    }
}

sl_status sl_lr_write(const sl_lr_volume *lr, FILE *f, sl_err *err)
{
    writer w = {.f = f};
    write_all(lr, &w);
    if (w.failed || ferror(f))
        return sl_err_set(err, SL_ERR_IO, "writing the LR-spline (%zu basis functions) failed",
                          lr->basis_count);
    return SL_OK;
}

static int ends_with_gz(const char *path)
{
    size_t n = strlen(path);
    return n >= 3 && strcmp(path + n - 3, ".gz") == 0;
}

sl_status sl_lr_write_file(const sl_lr_volume *lr, const char *path, sl_err *err)
{
    if (ends_with_gz(path)) {
        writer w = {.gz = gzopen(path, "wb6")};
        if (!w.gz)
            return sl_err_set(err, SL_ERR_IO, "cannot create %s", path);
        write_all(lr, &w);
        int rc = gzclose(w.gz);
        if (w.failed || rc != Z_OK)
            return sl_err_set(err, SL_ERR_IO, "writing the LR-spline to %s failed", path);
        return SL_OK;
    }
    FILE *f = fopen(path, "wb");
    if (!f)
        return sl_err_set(err, SL_ERR_IO, "cannot create %s", path);
    sl_status st = sl_lr_write(lr, f, err);
    if (fclose(f) != 0 && st == SL_OK)
        st = sl_err_set(err, SL_ERR_IO, "closing %s failed", path);
    if (st != SL_OK)
        sl_err_prefix(err, "%s: ", path);
    return st;
}
