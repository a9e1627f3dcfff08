// A stand-in for Nori's <nori/frame.h>: the local shading frame's static helpers.
#pragma once

#include <nori/vector.h>

NORI_NAMESPACE_BEGIN

struct Frame {
    Vector3f s, t;
    Normal3f n;

    Frame() {}
    Frame(const Vector3f &n_) : n(n_) { coordinateSystem(n_, s, t); }
    Vector3f toLocal(const Vector3f &v) const { return Vector3f(v.dot(s), v.dot(t), v.dot(n)); }
    Vector3f toWorld(const Vector3f &v) const { return s * v.x() + t * v.y() + n * v.z(); }

    static float cosTheta(const Vector3f &v) { return v.z(); }
    static float sinTheta2(const Vector3f &v) { return 1.0f - v.z() * v.z(); }
    static float sinTheta(const Vector3f &v) {
        float t = sinTheta2(v);
        return t <= 0.0f ? 0.0f : std::sqrt(t);
    }
    static float tanTheta(const Vector3f &v) {
        float t = 1.0f - v.z() * v.z();
        return t <= 0.0f ? 0.0f : std::sqrt(t) / v.z();
    }
    static float sinPhi(const Vector3f &v) {
        float s = sinTheta(v);
        return s == 0.0f ? 1.0f : clamp(v.y() / s, -1.0f, 1.0f);
    }
    static float cosPhi(const Vector3f &v) {
        float s = sinTheta(v);
        return s == 0.0f ? 1.0f : clamp(v.x() / s, -1.0f, 1.0f);
    }
    static float sinPhi2(const Vector3f &v) {
        return clamp(v.y() * v.y() / sinTheta2(v), 0.0f, 1.0f);
    }
    static float cosPhi2(const Vector3f &v) {
        return clamp(v.x() * v.x() / sinTheta2(v), 0.0f, 1.0f);
    }
};

NORI_NAMESPACE_END
