// make_lrsplines_fixtures.cpp — writes the test fixtures
// lrsplines_minspan3_scalar.lr.gz, lrsplines_minspan2_vector.lr.gz (tests/data/lr/)
// and tests/fuzz/corpus/lr/lrsplines_degenerate_segments.lr WITH the format's
// reference library, so they are in its exact layout, degenerate mesh
// rectangles included (issue 31). Not built by Sightline; nothing of the
// library is in this repository. Build it outside the tree (C++17, no
// dependencies; VikingScientist/LRsplines at 6b18f36):
//   git clone https://github.com/VikingScientist/LRsplines /tmp/lrsplines
//   cmake -S /tmp/lrsplines -B /tmp/lrsplines/build && cmake --build /tmp/lrsplines/build --target LRSpline
//   g++ -std=c++17 -I/tmp/lrsplines/include -I/tmp/lrsplines/build make_lrsplines_fixtures.cpp \
//       /tmp/lrsplines/build/lib/libLRSpline.a -o gen
//   ./gen 1 6 4 6 3 diagonal lrsplines_minspan3_scalar.lr   && gzip -9 -n lrsplines_minspan3_scalar.lr
//   ./gen 3 6 6 6 2 corner   lrsplines_minspan2_vector.lr   && gzip -9 -n lrsplines_minspan2_vector.lr
//   ./gen 1 6 4 6 1 diagonal lrsplines_degenerate_segments.lr
// What it does: a quadratic tensor-product volume on [0,1]^3 (n_d basis
// functions per direction, uniform open knots) whose coefficients are the
// blossoms of a known polynomial of degree <= 2 per direction (so the spline
// IS that polynomial; test_load_lr_degenerate.c has the same fields), refined
// `levels` times with LR_MINSPAN over a region, written with operator<<; it
// prints the counts, how many mesh rectangles are segments, and the library's
// own evaluation against the field at random points.
#include "LRSpline/LRSplineVolume.h"
#include "LRSpline/Element.h"
#include "LRSpline/MeshRectangle.h"
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <vector>
using namespace LR;

// Field terms: coefficient * u^a v^b w^c (a,b,c <= 2), per component.
struct term { double k; int e[3]; };
static std::vector<term> field[3];
static int dim = 1;

static double blossom(int e, double t1, double t2) { return e == 0 ? 1.0 : e == 1 ? 0.5 * (t1 + t2) : t1 * t2; }
static double poly(int c, const double x[3]) {
    double s = 0;
    for (auto &t : field[c]) s += t.k * std::pow(x[0], t.e[0]) * std::pow(x[1], t.e[1]) * std::pow(x[2], t.e[2]);
    return s;
}

int main(int argc, char **argv) {
    if (argc < 8) { fprintf(stderr, "gen dim n1 n2 n3 levels region out\n"); return 1; }
    dim = atoi(argv[1]);
    int n[3] = {atoi(argv[2]), atoi(argv[3]), atoi(argv[4])};
    int levels = atoi(argv[5]);
    const char *region = argv[6];
    if (dim == 1) {
        field[0] = {{0.5, {0, 0, 0}}, {1.0, {2, 0, 0}}, {-2.0, {1, 1, 1}}, {3.0, {0, 2, 1}}, {0.25, {0, 0, 1}}};
    } else {
        field[0] = {{1.0, {1, 1, 0}}, {-0.5, {0, 0, 2}}, {0.2, {0, 0, 0}}};
        field[1] = {{1.0, {0, 2, 0}}, {-1.0, {0, 0, 1}}, {0.75, {2, 1, 2}}};
        field[2] = {{1.0, {1, 0, 0}}, {1.5, {1, 1, 1}}, {-0.3, {0, 1, 0}}};
    }
    const int p = 3;
    std::vector<double> knots[3];
    for (int d = 0; d < 3; d++) {
        int inner = n[d] - p; // interior knots
        for (int i = 0; i < p; i++) knots[d].push_back(0.0);
        for (int i = 1; i <= inner; i++) knots[d].push_back((double)i / (inner + 1));
        for (int i = 0; i < p; i++) knots[d].push_back(1.0);
    }
    std::vector<double> coef;
    for (int k = 0; k < n[2]; k++)
        for (int j = 0; j < n[1]; j++)
            for (int i = 0; i < n[0]; i++) {
                int idx[3] = {i, j, k};
                for (int c = 0; c < dim; c++) {
                    double s = 0;
                    for (auto &t : field[c]) {
                        double prod = t.k;
                        for (int d = 0; d < 3; d++)
                            prod *= blossom(t.e[d], knots[d][idx[d] + 1], knots[d][idx[d] + 2]);
                        s += prod;
                    }
                    coef.push_back(s);
                }
            }
    LRSplineVolume *lr = new LRSplineVolume(n[0], n[1], n[2], p, p, p, knots[0].begin(), knots[1].begin(),
                                            knots[2].begin(), coef.begin(), dim, false);
    lr->setRefStrat(LR_MINSPAN);
    lr->setRefMultiplicity(1);
    for (int level = 0; level < levels; level++) {
        std::vector<int> pick;
        double h = std::pow(0.5, level);
        for (int i = 0; i < lr->nElements(); i++) {
            Element *e = lr->getElement(i);
            double m[3] = {0.5 * (e->umin() + e->umax()), 0.5 * (e->vmin() + e->vmax()), 0.5 * (e->wmin() + e->wmax())};
            double side = e->umax() - e->umin();
            bool in = false;
            if (!strcmp(region, "diagonal")) // a band along u = v, all w
                in = std::fabs(m[0] - m[1]) < 0.75 * side + 1e-12 && m[0] < 0.5 + 0.25 * h;
            else if (!strcmp(region, "corner")) // towards the corner (0.3, 0.3, 0.3)
                in = std::fabs(m[0] - 0.3) + std::fabs(m[1] - 0.3) + std::fabs(m[2] - 0.3) < 0.45 * h + side;
            else if (!strcmp(region, "line")) // around the line u = 0.3, v = 0.4 along w
                in = std::hypot(m[0] - 0.3, m[1] - 0.4) < 0.3 * h + 0.5 * side;
            if (in) pick.push_back(i);
        }
        lr->refineElement(pick);
    }
    std::ofstream out(argv[7]);
    out << *lr;
    out.close();
    int degenerate = 0, rects = 0;
    for (MeshRectangle *m : lr->getAllMeshRectangles()) {
        int flats = 0;
        for (int d = 0; d < 3; d++) flats += m->start_[d] == m->stop_[d];
        degenerate += flats > 1;
        rects++;
    }
    double worst = 0;
    srand(7);
    for (int s = 0; s < 2000; s++) {
        double x[3] = {rand() / (double)RAND_MAX, rand() / (double)RAND_MAX, rand() / (double)RAND_MAX};
        std::vector<double> pt;
        lr->point(pt, x[0], x[1], x[2]);
        for (int c = 0; c < dim; c++) worst = std::fmax(worst, std::fabs(pt[c] - poly(c, x)));
    }
    printf("%s: %d basis, %d elements, %d mesh rectangles of which %d degenerate; library eval vs field %.3g\n",
           argv[7], lr->nBasisFunctions(), lr->nElements(), rects, degenerate, worst);
    return 0;
}
