// Nori's warps served to `directlab check-sampler`: build this with a student's src/warp.cpp
// (helpers/nori/check-warps does, and runs every warp Nori's warptest knows).
//
//     ./warptest WARP [request.json]     WARP: square tent disk sphere hemisphere
//                                              cosine-hemisphere beckmann
//
// Points cross in float, as Nori computes them. The tent maps onto [-1, 1]^2 and is checked
// on the unit square after x -> (x + 1) / 2 (density times 4), as directlab's warp/tent.
// Beckmann's alpha is the request's "alpha" parameter.
#include <nori/vector.h>
#include <nori/warp.h>

#include "directlab_sampler.hpp"

#include <cstdio>
#include <string>

using namespace nori;
using directlab::Params;

static Point2f square(const double *u) { return Point2f((float) u[0], (float) u[1]); }
static Vector3f direction(const double *x) {
    return Vector3f((float) x[0], (float) x[1], (float) x[2]);
}
static bool put2(const Point2f &p, double *x) {
    x[0] = p.x(), x[1] = p.y();
    return true;
}
static bool put3(const Vector3f &v, double *x) {
    x[0] = v.x(), x[1] = v.y(), x[2] = v.z();
    return true;
}
static float alpha(const Params &p) { return (float) p.num("alpha", 0.3); }

int main(int argc, char **argv) {
    std::string warp = argc > 1 ? argv[1] : "";
    directlab::Sampler s;
    if (warp == "square") {
        s.sample = [](const double *u, const Params &, double *x) {
            return put2(Warp::squareToUniformSquare(square(u)), x);
        };
        s.pdf = [](const double *x, const Params &) {
            return (double) Warp::squareToUniformSquarePdf(Point2f((float) x[0], (float) x[1]));
        };
    } else if (warp == "tent") {
        s.sample = [](const double *u, const Params &, double *x) {
            Point2f p = Warp::squareToTent(square(u));
            return put2(Point2f(0.5f * (p.x() + 1.0f), 0.5f * (p.y() + 1.0f)), x);
        };
        s.pdf = [](const double *x, const Params &) {
            Point2f p((float) (2 * x[0] - 1), (float) (2 * x[1] - 1));
            return 4.0 * Warp::squareToTentPdf(p);
        };
    } else if (warp == "disk") {
        s.sample = [](const double *u, const Params &, double *x) {
            return put2(Warp::squareToUniformDisk(square(u)), x);
        };
        s.pdf = [](const double *x, const Params &) {
            return (double) Warp::squareToUniformDiskPdf(Point2f((float) x[0], (float) x[1]));
        };
    } else if (warp == "sphere") {
        s.sample = [](const double *u, const Params &, double *x) {
            return put3(Warp::squareToUniformSphere(square(u)), x);
        };
        s.pdf = [](const double *x, const Params &) {
            return (double) Warp::squareToUniformSpherePdf(direction(x));
        };
    } else if (warp == "hemisphere") {
        s.sample = [](const double *u, const Params &, double *x) {
            return put3(Warp::squareToUniformHemisphere(square(u)), x);
        };
        s.pdf = [](const double *x, const Params &) {
            return (double) Warp::squareToUniformHemispherePdf(direction(x));
        };
    } else if (warp == "cosine-hemisphere") {
        s.sample = [](const double *u, const Params &, double *x) {
            return put3(Warp::squareToCosineHemisphere(square(u)), x);
        };
        s.pdf = [](const double *x, const Params &) {
            return (double) Warp::squareToCosineHemispherePdf(direction(x));
        };
    } else if (warp == "beckmann") {
        s.sample = [](const double *u, const Params &p, double *x) {
            return put3(Warp::squareToBeckmann(square(u), alpha(p)), x);
        };
        s.pdf = [](const double *x, const Params &p) {
            return (double) Warp::squareToBeckmannPdf(direction(x), alpha(p));
        };
    } else {
        std::fprintf(stderr,
                     "usage: %s square|tent|disk|sphere|hemisphere|cosine-hemisphere|beckmann\n",
                     argv[0]);
        return 1;
    }
    return directlab::serve(s, argc, argv);
}
