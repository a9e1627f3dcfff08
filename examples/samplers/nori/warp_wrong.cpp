// warp.cpp with three mistakes students make, each rejected by
//     helpers/nori/check-warps examples/samplers/nori/warp_wrong.cpp
// the disk takes r = u instead of sqrt(u) (points bunch at the centre), the cosine
// hemisphere's pdf forgets the cosine, Beckmann's pdf forgets the cos(theta_m) of D cos.
#include <nori/frame.h>
#include <nori/vector.h>
#include <nori/warp.h>

NORI_NAMESPACE_BEGIN

Point2f Warp::squareToUniformSquare(const Point2f &sample) { return sample; }

float Warp::squareToUniformSquarePdf(const Point2f &p) {
    return ((p.array() >= 0).all() && (p.array() <= 1).all()) ? 1.0f : 0.0f;
}

// Each coordinate by inverting the tent's CDF on [-1, 1].
static float tent1(float u) { return u < 0.5f ? std::sqrt(2 * u) - 1 : 1 - std::sqrt(2 - 2 * u); }

Point2f Warp::squareToTent(const Point2f &sample) {
    return Point2f(tent1(sample.x()), tent1(sample.y()));
}

float Warp::squareToTentPdf(const Point2f &p) {
    float x = 1 - std::abs(p.x()), y = 1 - std::abs(p.y());
    return x >= 0 && y >= 0 ? x * y : 0.0f;
}

Point2f Warp::squareToUniformDisk(const Point2f &sample) {
    float r = sample.x(), phi = 2 * M_PI * sample.y();  // wrong: r = sqrt(u)
    return Point2f(r * std::cos(phi), r * std::sin(phi));
}

float Warp::squareToUniformDiskPdf(const Point2f &p) {
    return p.squaredNorm() <= 1 ? INV_PI : 0.0f;
}

Vector3f Warp::squareToUniformSphere(const Point2f &sample) {
    float z = 1 - 2 * sample.x(), r = std::sqrt(std::max(0.0f, 1 - z * z));
    float phi = 2 * M_PI * sample.y();
    return Vector3f(r * std::cos(phi), r * std::sin(phi), z);
}

float Warp::squareToUniformSpherePdf(const Vector3f &v) { return INV_FOURPI; }

Vector3f Warp::squareToUniformHemisphere(const Point2f &sample) {
    float z = sample.x(), r = std::sqrt(std::max(0.0f, 1 - z * z));
    float phi = 2 * M_PI * sample.y();
    return Vector3f(r * std::cos(phi), r * std::sin(phi), z);
}

float Warp::squareToUniformHemispherePdf(const Vector3f &v) {
    return v.z() >= 0 ? INV_TWOPI : 0.0f;
}

Vector3f Warp::squareToCosineHemisphere(const Point2f &sample) {
    Point2f d = squareToUniformDisk(sample);
    return Vector3f(d.x(), d.y(), std::sqrt(std::max(0.0f, 1 - d.squaredNorm())));
}

float Warp::squareToCosineHemispherePdf(const Vector3f &v) {
    return v.z() >= 0 ? INV_TWOPI : 0.0f;  // wrong: the cosine is missing
}

Vector3f Warp::squareToBeckmann(const Point2f &sample, float alpha) {
    float tan2 = -alpha * alpha * std::log(1 - sample.x());
    float cosTheta = 1 / std::sqrt(1 + tan2), phi = 2 * M_PI * sample.y();
    float sinTheta = std::sqrt(std::max(0.0f, 1 - cosTheta * cosTheta));
    return Vector3f(sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta);
}

float Warp::squareToBeckmannPdf(const Vector3f &m, float alpha) {
    if (m.z() <= 0) return 0.0f;
    float c2 = m.z() * m.z(), tan2 = (1 - c2) / c2;
    return std::exp(-tan2 / (alpha * alpha)) / (M_PI * alpha * alpha * c2 * c2);  // wrong: no cos
}

NORI_NAMESPACE_END
