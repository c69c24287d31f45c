/* test_lr_lookup.c — the CPU element look-up structures (renderer/lrspline/
 * lr_lookup*.c) against sl_lr_find_element_linear, the reference.
 *
 * Volumes: tensor products with uniform, dyadic and non-uniform knots, and
 * strongly locally refined element meshes (tests/support/lr_test_volumes.h:
 * boxes split in 8 near a point down to 1:2^10 and near a sphere; split at
 * the middle = dyadic, or at 0.4 = non-dyadic). For each, 10^6 probe points
 * (10^5 in sanitizer builds)
 * (uniform, on element faces/edges/corners, beside them, on the domain's
 * faces/edges/corners, just outside) must give exactly the reference element
 * (or -1) for every applicable structure and several forest sizes. Refusals:
 * octree on non-dyadic knots (message names the knot), texture beyond its
 * grid limit and on irregular knots. Statistics are sane (depth bounds,
 * direct blocks, the kdtree depth near log2 of the element count).
 * Single-threaded.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../support/lr_test_volumes.h"
#include "lrspline/sl_lr_lookup.h"
#include "sl_test.h"

/* 10^6 probes per volume; 10^5 under a sanitizer (20x slower there, and
 * the ctest timeout is 300 s on a shared machine). */
#if defined(__SANITIZE_ADDRESS__)
#define PROBES 100000
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(undefined_behavior_sanitizer)
#define PROBES 100000
#endif
#endif
#ifndef PROBES
#define PROBES 1000000
#endif

typedef struct probe_set {
    double (*p)[3];
    long *ref;
    size_t n;
} probe_set;

static int probes_make(probe_set *ps, const sl_lr_volume *lr, size_t n, uint64_t seed)
{
    ps->p = malloc(n * sizeof *ps->p);
    ps->ref = malloc(n * sizeof *ps->ref);
    ps->n = n;
    if (!ps->p || !ps->ref)
        return 0;
    lrt_rng r = {seed};
    for (size_t i = 0; i < n; i++) {
        lrt_probe(lr, &r, ps->p[i]);
        ps->ref[i] = sl_lr_find_element_linear(lr, ps->p[i]);
    }
    /* The exact corners and just-outside points of the domain, and NaN. */
    for (int c = 0; c < 8 && n >= 64; c++)
        for (int d = 0; d < 3; d++)
            ps->p[c][d] = (c >> d & 1) ? lr->domain_hi[d] : lr->domain_lo[d];
    if (n >= 64) {
        for (int d = 0; d < 3; d++) {
            ps->p[8][d] = 0.5 * (lr->domain_lo[d] + lr->domain_hi[d]);
            ps->p[9][d] = nextafter(lr->domain_hi[d], INFINITY);
        }
        ps->p[8][1] = NAN;
        for (int i = 0; i < 10; i++)
            ps->ref[i] = sl_lr_find_element_linear(lr, ps->p[i]);
    }
    return 1;
}

static void probes_free(probe_set *ps)
{
    free(ps->p);
    free(ps->ref);
}

/* Builds `kind` and checks every probe; returns the build status. */
static sl_status check_kind(const char *name, const sl_lr_volume *lr, const probe_set *ps, sl_lr_lookup_kind kind,
                            int forest, sl_err *err)
{
    sl_lr_lookup lk;
    sl_status st = sl_lr_lookup_init(&lk, lr, kind, forest, err);
    if (st != SL_OK)
        return st;
    size_t bad = 0, outside = 0, first = 0;
    for (size_t i = 0; i < ps->n; i++) {
        long e = sl_lr_lookup_find(&lk, ps->p[i]);
        outside += ps->ref[i] < 0;
        if (e != ps->ref[i] && bad++ == 0)
            first = i;
    }
    SL_CHECK_MSG(bad == 0, "%s %s/%d: %zu of %zu probes differ from the linear search; first (%.17g %.17g %.17g) "
                 "gives %ld, reference %ld", name, sl_lr_lookup_kind_name(kind), forest, bad, ps->n,
                 ps->p[first][0], ps->p[first][1], ps->p[first][2], sl_lr_lookup_find(&lk, ps->p[first]),
                 ps->ref[first]);
    SL_CHECK_MSG(outside > ps->n / 50 && outside < ps->n / 2, "%s: %zu probes outside of %zu", name, outside, ps->n);
    const sl_lr_lookup_stats *s = &lk.stats;
    SL_CHECK(s->depth_min <= s->depth_max && s->depth_mean >= s->depth_min && s->depth_mean <= s->depth_max);
    SL_CHECK(s->depth_var >= 0.0 && s->bytes > 0);
    printf("  %-10s %-8s n=%-4d trees %8zu nodes %8zu depth %d/%.3g/%d var %.3g  %.1f KiB  build %.1f ms\n", name,
           sl_lr_lookup_kind_name(lk.kind), forest, s->trees, s->nodes, s->depth_min, s->depth_mean, s->depth_max,
           s->depth_var, (double)s->bytes / 1024.0, s->build_ms);
    if (kind == SL_LR_LOOKUP_KDTREE) {
        /* Depth-balanced: within a few levels of log2(elements). */
        double lg = log2((double)lr->element_count);
        SL_CHECK_MSG(s->depth_max <= 2.0 * lg + 4.0, "kdtree depth %d for %zu elements", s->depth_max,
                     lr->element_count);
    }
    sl_lr_lookup_deinit(&lk);
    return SL_OK;
}

static void check_all(const char *name, const sl_lr_volume *lr, int expect_texture, int expect_octree)
{
    {
        /* auto: the texture where it applies, else the k-d forest. */
        sl_err e0;
        sl_lr_lookup a;
        sl_lr_lookup_kind want = expect_texture ? SL_LR_LOOKUP_TEXTURE : SL_LR_LOOKUP_KDFOREST;
        SL_CHECK(sl_lr_lookup_init(&a, lr, SL_LR_LOOKUP_AUTO, 0, &e0) == SL_OK);
        SL_CHECK_MSG(a.kind == want, "%s: auto chose %s, expected %s", name, sl_lr_lookup_kind_name(a.kind),
                     sl_lr_lookup_kind_name(want));
        sl_lr_lookup_deinit(&a);
    }
    probe_set ps;
    if (!probes_make(&ps, lr, PROBES, 0x9E3779B97F4A7C15ull ^ lr->element_count)) {
        SL_CHECK(!"out of memory");
        probes_free(&ps);
        return;
    }
    sl_err err;
    sl_status st = check_kind(name, lr, &ps, SL_LR_LOOKUP_TEXTURE, 0, &err);
    SL_CHECK_MSG((st == SL_OK) == expect_texture, "%s texture: %s", name, st ? err.message : "built");
    if (st != SL_OK) {
        SL_CHECK(st == SL_ERR_UNSUPPORTED && strstr(err.message, "texture"));
        printf("  %-10s texture refused: %s\n", name, err.message);
    }
    st = check_kind(name, lr, &ps, SL_LR_LOOKUP_OCTREE, 0, &err);
    SL_CHECK_MSG((st == SL_OK) == expect_octree, "%s octree: %s", name, st ? err.message : "built");
    if (st != SL_OK) {
        SL_CHECK(st == SL_ERR_UNSUPPORTED && strstr(err.message, "not dyadic"));
        printf("  %-10s octree refused: %s\n", name, err.message);
    }
    st = check_kind(name, lr, &ps, SL_LR_LOOKUP_KDTREE, 0, &err);
    SL_CHECK_MSG(st == SL_OK, "%s kdtree: %s", name, err.message);
    static const int forests[] = {1, 2, 5, 8, 32};
    for (size_t f = 0; f < sizeof forests / sizeof *forests; f++) {
        st = check_kind(name, lr, &ps, SL_LR_LOOKUP_KDFOREST, forests[f], &err);
        SL_CHECK_MSG(st == SL_OK, "%s kdforest %d: %s", name, forests[f], err.message);
    }
    st = check_kind(name, lr, &ps, SL_LR_LOOKUP_AUTO, 0, &err);
    SL_CHECK_MSG(st == SL_OK, "%s auto: %s", name, err.message);
    probes_free(&ps);
}

static void test_tensor(void)
{
    sl_err err;
    sl_lr_volume lr;
    /* Uniform knots on a domain whose bounds are not floats. */
    double u0[] = {0.1, 0.35, 0.6, 0.85, 1.1}, u1[] = {-2, -1, 0, 1, 2}, u2[] = {3, 3.5, 4, 4.5, 5};
    const double *bu[3] = {u0, u1, u2};
    int mu[3] = {5, 5, 5};
    SL_CHECK(lrt_tensor(&lr, 3, bu, mu, &err) == SL_OK);
    check_all("uniform", &lr, 1, 1);
    sl_lr_free(&lr);
    /* Dyadic, not uniform: texture at the finest grid, octree. */
    double d0[] = {0, 0.25, 0.375, 0.5, 1}, d1[] = {0, 0.0625, 1}, d2[] = {-1, 0, 0.5, 0.75, 1};
    const double *bd[3] = {d0, d1, d2};
    int md[3] = {5, 3, 5};
    SL_CHECK(lrt_tensor(&lr, 4, bd, md, &err) == SL_OK);
    check_all("dyadic", &lr, 1, 1);
    sl_lr_free(&lr);
    /* Non-uniform: no texture, no octree. */
    double n0[] = {0, 0.1, 1.0 / 3.0, 0.37, 0.9, 1.0}, n1[] = {0, M_PI / 10, 1}, n2[] = {0, 0.5, 0.51, 2};
    const double *bn[3] = {n0, n1, n2};
    int mn[3] = {6, 3, 4};
    SL_CHECK(lrt_tensor(&lr, 2, bn, mn, &err) == SL_OK);
    check_all("nonuniform", &lr, 0, 0);
    sl_lr_free(&lr);
    /* Texture beyond its cell limit: 512^3 cells for knots at 1/512. */
    double t0[] = {0, 1.0 / 512, 1};
    const double *bt[3] = {t0, t0, t0};
    int mt[3] = {3, 3, 3};
    SL_CHECK(lrt_tensor(&lr, 2, bt, mt, &err) == SL_OK);
    sl_lr_lookup lk;
    sl_status st = sl_lr_lookup_init(&lk, &lr, SL_LR_LOOKUP_TEXTURE, 0, &err);
    SL_CHECK_MSG(st == SL_ERR_UNSUPPORTED && strstr(err.message, "512 x 512 x 512") && strstr(err.message, "limit"),
                 "%s", st ? err.message : "built");
    check_all("fine-grid", &lr, 0, 1);
    sl_lr_free(&lr);
    /* An octree past its cell cap: a knot at 2^-12 across the domain. */
    double f0[] = {0, 1.0 / 4096, 1};
    const double *bf[3] = {f0, f0, f0};
    SL_CHECK(lrt_tensor(&lr, 2, bf, mt, &err) == SL_OK);
    st = sl_lr_lookup_init(&lk, &lr, SL_LR_LOOKUP_OCTREE, 0, &err);
    SL_CHECK_MSG(st == SL_ERR_LIMIT && strstr(err.message, "split cells"), "%s", st ? err.message : "built");
    SL_CHECK(sl_lr_lookup_init(&lk, &lr, SL_LR_LOOKUP_AUTO, 0, &err) == SL_OK && lk.kind == SL_LR_LOOKUP_KDFOREST);
    sl_lr_lookup_deinit(&lk);
    sl_lr_free(&lr);
}

static void test_refined(void)
{
    sl_err err;
    sl_lr_volume lr;
    double lo[3] = {0.1, -0.3, 2.0}, hi[3] = {1.7, 0.9, 2.5};
    /* Dyadic (base grid 4^3), 1:2^10 around a point, a sphere refined 3 levels. */
    lrt_refine r = {.point = {0.6123, 0.2, 2.3}, .point_level = 10, .centre = {0.9, 0.3, 2.25}, .radius = 0.35,
                    .surface_level = 3, .t = 0.5};
    SL_CHECK(lrt_refined(&lr, lo, hi, 4, &r, &err) == SL_OK);
    printf("refined dyadic: %zu elements\n", lr.element_count);
    check_all("refined", &lr, 0, 1);
    sl_err e2;
    sl_lr_lookup lk;
    SL_CHECK(sl_lr_lookup_init(&lk, &lr, SL_LR_LOOKUP_TEXTURE, 0, &e2) == SL_ERR_UNSUPPORTED &&
             strstr(e2.message, "no regular grid of at most 1024"));
    sl_lr_free(&lr);
    /* The same at the point only on a domain [0,1]^3 split at the middle:
     * level 10 = grid 1024 per direction; texture would need 2^30 cells. */
    double ulo[3] = {0, 0, 0}, uhi[3] = {1, 1, 1};
    lrt_refine rp = {.point = {0.3, 0.7, 0.5}, .point_level = 10, .t = 0.5};
    SL_CHECK(lrt_refined(&lr, ulo, uhi, 1, &rp, &err) == SL_OK);
    SL_CHECK(sl_lr_lookup_init(&lk, &lr, SL_LR_LOOKUP_TEXTURE, 0, &e2) == SL_ERR_UNSUPPORTED &&
             strstr(e2.message, "1024 x 1024 x 1024"));
    check_all("point", &lr, 0, 1);
    sl_lr_free(&lr);
    /* Non-dyadic splits (base 3^3, 0.4 of each side): octree refuses, others work. */
    lrt_refine rn = r;
    rn.t = 0.4;
    rn.point_level = 8;
    SL_CHECK(lrt_refined(&lr, lo, hi, 3, &rn, &err) == SL_OK);
    printf("refined non-dyadic: %zu elements\n", lr.element_count);
    check_all("nondyadic", &lr, 0, 0);
    {
        sl_status st = sl_lr_lookup_init(&lk, &lr, SL_LR_LOOKUP_OCTREE, 0, &e2);
        SL_CHECK_MSG(st == SL_ERR_UNSUPPORTED && strstr(e2.message, "knot ") && strstr(e2.message, "(element "),
                     "%s", e2.message);
    }
    sl_lr_free(&lr);
}

static void test_kinds(void)
{
    sl_err err;
    sl_lr_lookup_kind k;
    SL_CHECK(sl_lr_lookup_kind_parse("kdforest", &k, &err) == SL_OK && k == SL_LR_LOOKUP_KDFOREST);
    SL_CHECK(sl_lr_lookup_kind_parse("octree", &k, &err) == SL_OK && k == SL_LR_LOOKUP_OCTREE);
    SL_CHECK(sl_lr_lookup_kind_parse("bsp", &k, &err) == SL_ERR_INVALID && strstr(err.message, "kdforest"));
    SL_CHECK(strcmp(sl_lr_lookup_kind_name(SL_LR_LOOKUP_TEXTURE), "texture") == 0);
    /* Bad forest sizes are refused. */
    double b0[] = {0, 1};
    const double *bb[3] = {b0, b0, b0};
    int mb[3] = {2, 2, 2};
    sl_lr_volume lr;
    SL_CHECK(lrt_tensor(&lr, 1, bb, mb, &err) == SL_OK);
    sl_lr_lookup lk;
    SL_CHECK(sl_lr_lookup_init(&lk, &lr, SL_LR_LOOKUP_KDFOREST, 129, &err) == SL_ERR_INVALID);
    SL_CHECK(sl_lr_lookup_init(&lk, &lr, SL_LR_LOOKUP_KDTREE, 0, &err) == SL_OK);
    double p[3] = {1, 1, 1}, q[3] = {1, 1, 1.0000001};
    SL_CHECK(sl_lr_lookup_find(&lk, p) == 0 && sl_lr_lookup_find(&lk, q) == -1);
    sl_lr_lookup_deinit(&lk);
    sl_lr_free(&lr);
}

int main(void)
{
    test_kinds();
    test_tensor();
    test_refined();
    SL_TEST_END();
}
