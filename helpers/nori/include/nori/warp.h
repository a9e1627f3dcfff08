// A stand-in for Nori's <nori/warp.h>: the warps of Nori's warptest, declared as Nori
// declares them, so a student's src/warp.cpp compiles unchanged.
#pragma once

#include <nori/common.h>
#include <nori/sampler.h>

NORI_NAMESPACE_BEGIN

class Warp {
  public:
    static Point2f squareToUniformSquare(const Point2f &sample);
    static float squareToUniformSquarePdf(const Point2f &p);
    static Point2f squareToTent(const Point2f &sample);
    static float squareToTentPdf(const Point2f &p);
    static Point2f squareToUniformDisk(const Point2f &sample);
    static float squareToUniformDiskPdf(const Point2f &p);
    static Vector3f squareToUniformSphere(const Point2f &sample);
    static float squareToUniformSpherePdf(const Vector3f &v);
    static Vector3f squareToUniformHemisphere(const Point2f &sample);
    static float squareToUniformHemispherePdf(const Vector3f &v);
    static Vector3f squareToCosineHemisphere(const Point2f &sample);
    static float squareToCosineHemispherePdf(const Vector3f &v);
    static Vector3f squareToBeckmann(const Point2f &sample, float alpha);
    static float squareToBeckmannPdf(const Vector3f &m, float alpha);
};

NORI_NAMESPACE_END
