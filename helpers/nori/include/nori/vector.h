// A stand-in for Nori's <nori/vector.h>: vectors and points as Eigen column vectors.
#pragma once

#include <nori/common.h>

NORI_NAMESPACE_BEGIN

template <typename Scalar_, int Dimension_>
struct TVector : public Eigen::Matrix<Scalar_, Dimension_, 1> {
    enum { Dimension = Dimension_ };
    typedef Scalar_ Scalar;
    typedef Eigen::Matrix<Scalar, Dimension, 1> Base;

    TVector(Scalar value = (Scalar) 0) { Base::setConstant(value); }
    TVector(Scalar x, Scalar y) : Base(x, y) {}
    TVector(Scalar x, Scalar y, Scalar z) : Base(x, y, z) {}
    TVector(Scalar x, Scalar y, Scalar z, Scalar w) : Base(x, y, z, w) {}
    template <typename Derived> TVector(const Eigen::MatrixBase<Derived> &p) : Base(p) {}
    template <typename Derived> TVector &operator=(const Eigen::MatrixBase<Derived> &p) {
        this->Base::operator=(p);
        return *this;
    }
};

template <typename Scalar_, int Dimension_>
struct TPoint : public Eigen::Matrix<Scalar_, Dimension_, 1> {
    enum { Dimension = Dimension_ };
    typedef Scalar_ Scalar;
    typedef Eigen::Matrix<Scalar, Dimension, 1> Base;

    TPoint(Scalar value = (Scalar) 0) { Base::setConstant(value); }
    TPoint(Scalar x, Scalar y) : Base(x, y) {}
    TPoint(Scalar x, Scalar y, Scalar z) : Base(x, y, z) {}
    TPoint(Scalar x, Scalar y, Scalar z, Scalar w) : Base(x, y, z, w) {}
    template <typename Derived> TPoint(const Eigen::MatrixBase<Derived> &p) : Base(p) {}
    template <typename Derived> TPoint &operator=(const Eigen::MatrixBase<Derived> &p) {
        this->Base::operator=(p);
        return *this;
    }
};

struct Normal3f : public Eigen::Matrix<float, 3, 1> {
    typedef Eigen::Matrix<float, 3, 1> Base;
    Normal3f(float value = 0.0f) { Base::setConstant(value); }
    Normal3f(float x, float y, float z) : Base(x, y, z) {}
    template <typename Derived> Normal3f(const Eigen::MatrixBase<Derived> &p) : Base(p) {}
    template <typename Derived> Normal3f &operator=(const Eigen::MatrixBase<Derived> &p) {
        this->Base::operator=(p);
        return *this;
    }
};

/// An orthonormal basis (b, c) completing the unit vector a.
inline void coordinateSystem(const Vector3f &a, Vector3f &b, Vector3f &c) {
    if (std::abs(a.x()) > std::abs(a.y())) {
        float inv = 1.0f / std::sqrt(a.x() * a.x() + a.z() * a.z());
        c = Vector3f(a.z() * inv, 0.0f, -a.x() * inv);
    } else {
        float inv = 1.0f / std::sqrt(a.y() * a.y() + a.z() * a.z());
        c = Vector3f(0.0f, a.z() * inv, -a.y() * inv);
    }
    b = c.cross(a);
}

inline Vector3f sphericalDirection(float theta, float phi) {
    return Vector3f(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                    std::cos(theta));
}

inline Point2f sphericalCoordinates(const Vector3f &v) {
    float phi = std::atan2(v.y(), v.x());
    return Point2f(std::acos(clamp(v.z(), -1.0f, 1.0f)), phi < 0 ? phi + 2 * M_PI : phi);
}

NORI_NAMESPACE_END
