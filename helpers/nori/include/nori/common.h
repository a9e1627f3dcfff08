// A stand-in for Nori's <nori/common.h>, enough to compile a student's src/warp.cpp outside
// Nori (with Eigen only): the same namespace macros, constants (float, as in Nori), vector
// typedefs, NoriException and small helpers. With a Nori checkout, build against its own
// headers instead (helpers/nori/check-warps --nori DIR).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#define NORI_NAMESPACE_BEGIN namespace nori {
#define NORI_NAMESPACE_END }

#define Epsilon 1e-4f

#undef M_PI
#define M_PI 3.14159265358979323846f
#define INV_PI 0.31830988618379067154f
#define INV_TWOPI 0.15915494309189533577f
#define INV_FOURPI 0.07957747154594766788f
#define SQRT_TWO 1.41421356237309504880f
#define INV_SQRT_TWO 0.70710678118654752440f

NORI_NAMESPACE_BEGIN

template <typename Scalar, int Dimension> struct TVector;
template <typename Scalar, int Dimension> struct TPoint;

typedef TVector<float, 2> Vector2f;
typedef TVector<float, 3> Vector3f;
typedef TVector<float, 4> Vector4f;
typedef TVector<double, 2> Vector2d;
typedef TVector<double, 3> Vector3d;
typedef TVector<int, 2> Vector2i;
typedef TVector<int, 3> Vector3i;
typedef TPoint<float, 2> Point2f;
typedef TPoint<float, 3> Point3f;
typedef TPoint<double, 2> Point2d;
typedef TPoint<double, 3> Point3d;
typedef TPoint<int, 2> Point2i;

class Sampler;
class BSDF;

using std::cerr;
using std::cout;
using std::endl;

/// Nori's exception; the message is the format string followed by its arguments.
class NoriException : public std::runtime_error {
  public:
    template <typename... Args>
    NoriException(const char *fmt, const Args &...args) : std::runtime_error(join(fmt, args...)) {}

  private:
    template <typename... Args> static std::string join(const char *fmt, const Args &...args) {
        std::ostringstream s;
        s << fmt;
        ((s << ' ' << args), ...);
        return s.str();
    }
};

enum EMeasure { EUnknownMeasure = 0, ESolidAngle, EDiscrete };

inline float radToDeg(float value) { return value * (180.0f / M_PI); }
inline float degToRad(float value) { return value * (M_PI / 180.0f); }
inline float clamp(float value, float lo, float hi) { return std::min(std::max(value, lo), hi); }
inline int clamp(int value, int lo, int hi) { return std::min(std::max(value, lo), hi); }
inline float lerp(float t, float v1, float v2) { return (1.0f - t) * v1 + t * v2; }
inline int mod(int a, int b) {
    int r = a % b;
    return r < 0 ? r + b : r;
}

NORI_NAMESPACE_END
