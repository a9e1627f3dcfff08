// A stand-in for Nori's <nori/sampler.h> (warp.h includes it; warps do not use it).
#pragma once

#include <nori/common.h>

NORI_NAMESPACE_BEGIN

class Sampler;

NORI_NAMESPACE_END
