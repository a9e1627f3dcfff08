// directlab's own warps in C++, checked by `directlab check-sampler --case`: each maps the
// uniform numbers as directlab's Rust code does, so it gets the built-in case's p-value.
//
//     c++ -O2 -std=c++17 -I helpers/cpp examples/samplers/cpp/directlab_warps.cpp -o warps
//     directlab check-sampler --case warp/cosine-hemisphere -- ./warps cosine-hemisphere
//     directlab check-sampler --case warp/spherical-triangle -- ./warps spherical-triangle
//     directlab check-sampler --case warp/beckmann-a0.5-dcos -- ./warps beckmann
//
// `cosine-hemisphere --wrong cosine` claims the uniform hemisphere's pdf (the missing
// cosine), `--wrong horizon` a pdf 20 % high within 10 degrees of the horizon, `--wrong
// outside` returns some points below the hemisphere that its pdf calls impossible.
#include "directlab_sampler.hpp"

#include <array>
#include <cmath>
#include <cstring>
#include <string>

using directlab::Params;
using V3 = std::array<double, 3>;

static const double PI = 3.14159265358979323846;
static std::string wrong;

static double dot(const V3 &a, const V3 &b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static V3 cross(const V3 &a, const V3 &b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
static V3 add(const V3 &a, const V3 &b, double s = 1) {
    return {a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]};
}
static V3 scale(const V3 &a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
static V3 unit(const V3 &a) { return scale(a, 1 / std::sqrt(dot(a, a))); }

static bool uniform_disk(const double *u, const Params &, double *x) {
    double r = std::sqrt(u[0]), phi = 2 * PI * u[1];
    x[0] = r * std::cos(phi);
    x[1] = r * std::sin(phi);
    return true;
}

static double disk_pdf(const double *x, const Params &) {
    return x[0] * x[0] + x[1] * x[1] <= 1 ? 1 / PI : 0.0;
}

static void concentric(const double *u, double *d) {
    double ox = 2 * u[0] - 1, oy = 2 * u[1] - 1;
    if (ox == 0 && oy == 0) {
        d[0] = d[1] = 0;
        return;
    }
    bool wide = std::fabs(ox) > std::fabs(oy);
    double r = wide ? ox : oy;
    double phi = wide ? PI / 4 * (oy / ox) : PI / 2 - PI / 4 * (ox / oy);
    d[0] = r * std::cos(phi);
    d[1] = r * std::sin(phi);
}

static bool concentric_disk(const double *u, const Params &, double *x) {
    concentric(u, x);
    return true;
}

static bool cosine_hemisphere(const double *u, const Params &, double *x) {
    concentric(u, x);
    x[2] = std::sqrt(std::fmax(0.0, 1 - x[0] * x[0] - x[1] * x[1]));
    if (wrong == "outside" && u[0] > 0.999) x[2] = -x[2];
    return true;
}

static double cosine_hemisphere_pdf(const double *d, const Params &) {
    if (wrong == "cosine") return d[2] > 0 ? 1 / (2 * PI) : 0.0;
    double p = std::fmax(d[2], 0.0) / PI;
    if (wrong == "horizon" && d[2] < std::sin(10 * PI / 180)) p *= 1.2;
    return p;
}

static std::array<V3, 3> vertices(const Params &p) {
    std::vector<double> v;
    if (const directlab::Json *j = p.json.get("vertices"))
        for (const auto &pt : j->array)
            for (const auto &c : pt.array) v.push_back(c.number);
    if (v.size() != 9) throw std::runtime_error("spherical-triangle needs 'vertices'");
    return {V3{v[0], v[1], v[2]}, V3{v[3], v[4], v[5]}, V3{v[6], v[7], v[8]}};
}

// The angle at p between the arcs to q and to r.
static double corner(const V3 &p, const V3 &q, const V3 &r) {
    V3 e1 = cross(p, q), e2 = cross(p, r);
    double c = dot(e1, e2) / std::sqrt(dot(e1, e1) * dot(e2, e2));
    return std::acos(std::fmax(-1.0, std::fmin(1.0, c)));
}

// Arvo's area-preserving map, step by step as directlab's sample_spherical_triangle.
static bool spherical_triangle(const double *u, const Params &p, double *x) {
    auto v = vertices(p);
    V3 a = unit(v[0]), b = unit(v[1]), c = unit(v[2]);
    double alpha = corner(a, b, c);
    double area = alpha + corner(b, c, a) + corner(c, a, b) - PI;
    double phi = PI + u[0] * area - alpha, s = std::sin(phi), t = std::cos(phi);
    double k1 = t + std::cos(alpha), k2 = s - std::sin(alpha) * dot(a, b);
    double num = k2 + (k2 * t - k1 * s) * std::cos(alpha);
    double cos_bp = num / ((k2 * s + k1 * t) * std::sin(alpha));
    cos_bp = std::fmax(-1.0, std::fmin(1.0, cos_bp));
    V3 c_perp = unit(add(c, a, -dot(c, a)));
    V3 cp = add(scale(a, cos_bp), c_perp, std::sqrt(std::fmax(0.0, 1 - cos_bp * cos_bp)));
    double cos_t = 1 - u[1] * (1 - dot(cp, b));
    V3 cp_perp = unit(add(cp, b, -dot(cp, b)));
    V3 w = unit(add(scale(b, cos_t), cp_perp, std::sqrt(std::fmax(0.0, 1 - cos_t * cos_t))));
    std::memcpy(x, w.data(), sizeof w);
    return true;
}

static double spherical_triangle_pdf(const double *d, const Params &p) {
    auto v = vertices(p);
    V3 dir{d[0], d[1], d[2]};
    V3 n = cross(add(v[1], v[0], -1), add(v[2], v[0], -1));
    double t = dot(n, v[0]) / dot(n, dir);
    if (!(t > 0)) return 0;
    V3 hit = scale(dir, t);
    for (int i = 0; i < 3; ++i)
        if (dot(cross(add(v[(i + 1) % 3], v[i], -1), add(hit, v[i], -1)), n) < 0) return 0;
    V3 a = unit(v[0]), b = unit(v[1]), c = unit(v[2]);
    double den = 1 + dot(a, b) + dot(b, c) + dot(c, a);
    double omega = 2 * std::atan2(std::fabs(dot(a, cross(b, c))), den);
    return 1 / omega;
}

// Normals with density D(m) cos(theta_m): tan(theta) = alpha sqrt(-ln(1 - u0)).
static bool beckmann(const double *u, const Params &p, double *x) {
    double au = p.num("alpha_u"), av = p.num("alpha_v");
    double r = std::sqrt(-std::log1p(-u[0])), phi = 2 * PI * u[1];
    V3 m = unit({-r * std::cos(phi) * au, -r * std::sin(phi) * av, 1.0});
    std::memcpy(x, m.data(), sizeof m);
    return true;
}

static double beckmann_pdf(const double *m, const Params &p) {
    double au = p.num("alpha_u"), av = p.num("alpha_v"), z2 = m[2] * m[2];
    if (!(m[2] > 0) || z2 * z2 == 0) return 0;
    double e = (m[0] / au) * (m[0] / au) + (m[1] / av) * (m[1] / av);
    return std::exp(-e / z2) / (PI * au * av * z2 * z2) * m[2];
}

int main(int argc, char **argv) {
    std::string warp = argc > 1 ? argv[1] : "";
    for (int i = 1; i + 1 < argc; ++i)
        if (std::string(argv[i]) == "--wrong") wrong = argv[i + 1];
    directlab::Sampler s;
    if (warp == "uniform-disk") s.sample = uniform_disk, s.pdf = disk_pdf;
    else if (warp == "concentric-disk") s.sample = concentric_disk, s.pdf = disk_pdf;
    else if (warp == "cosine-hemisphere")
        s.sample = cosine_hemisphere, s.pdf = cosine_hemisphere_pdf;
    else if (warp == "spherical-triangle")
        s.sample = spherical_triangle, s.pdf = spherical_triangle_pdf;
    else if (warp == "beckmann") s.sample = beckmann, s.pdf = beckmann_pdf;
    else {
        std::fprintf(stderr, "usage: %s uniform-disk|concentric-disk|cosine-hemisphere|"
                             "spherical-triangle|beckmann [--wrong cosine|horizon|outside]\n",
                     argv[0]);
        return 1;
    }
    return directlab::serve(s, argc, argv);
}
