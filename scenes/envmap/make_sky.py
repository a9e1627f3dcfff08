#!/usr/bin/env python3
"""Writes sky.exr, the bundled environment map (issue 71): a procedural latitude-longitude
sky in Mitsuba's envmap convention (u = phi / 2 pi from -z towards +x, v = theta / pi from
+y up), 256 x 128 RGB float32, uncompressed scanlines, with no dependencies.

- sky: a blue gradient, brighter towards the horizon, with a glow around the sun;
- sun: a disc of angular radius 2.5 degrees at 35 degrees elevation, azimuth 60 degrees,
  radiance 2000 (about 70 % of the light the map sends to a sphere, luminance x solid angle);
- ground (below the horizon): a dim brown, 0.05.

    python3 scenes/envmap/make_sky.py [out.exr]
"""

import math
import struct
import sys

W, H = 256, 128
SUN_ELEVATION = math.radians(35.0)
SUN_AZIMUTH = math.radians(60.0)
SUN_RADIUS = math.radians(2.5)
SUN_RADIANCE = (2000.0, 1900.0, 1700.0)


def direction(u, v):
    theta, phi = math.pi * v, 2.0 * math.pi * u
    return (math.sin(theta) * math.sin(phi), math.cos(theta), -math.sin(theta) * math.cos(phi))


def radiance(d):
    sun = direction(SUN_AZIMUTH / (2.0 * math.pi), 0.5 - SUN_ELEVATION / math.pi)
    cos_sun = sum(a * b for a, b in zip(d, sun))
    if cos_sun >= math.cos(SUN_RADIUS):
        return SUN_RADIANCE
    up = d[1]
    if up < 0.0:
        return (0.05, 0.04, 0.03)
    horizon = 1.0 - up
    glow = 2.0 * max(cos_sun, 0.0) ** 16
    return (0.25 + 0.5 * horizon + glow, 0.45 + 0.4 * horizon + 0.8 * glow, 1.0 + 0.2 * horizon + 0.4 * glow)


def exr(pixels, w, h):
    """An uncompressed scanline RGB float32 OpenEXR file (channels B, G, R: sorted by name)."""
    def attr(name, kind, data):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(data)) + data

    chlist = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in "BGR") + b"\0"
    header = b"".join([
        struct.pack("<ii", 20000630, 2),
        attr("channels", "chlist", chlist),
        attr("compression", "compression", b"\0"),
        attr("dataWindow", "box2i", struct.pack("<iiii", 0, 0, w - 1, h - 1)),
        attr("displayWindow", "box2i", struct.pack("<iiii", 0, 0, w - 1, h - 1)),
        attr("lineOrder", "lineOrder", b"\0"),
        attr("pixelAspectRatio", "float", struct.pack("<f", 1.0)),
        attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0)),
        attr("screenWindowWidth", "float", struct.pack("<f", 1.0)),
        b"\0",
    ])
    line_bytes = 3 * 4 * w
    first = len(header) + 8 * h
    offsets = b"".join(struct.pack("<Q", first + y * (8 + line_bytes)) for y in range(h))
    lines = []
    for y in range(h):
        row = pixels[y * w:(y + 1) * w]
        data = b"".join(struct.pack(f"<{w}f", *[p[c] for p in row]) for c in (2, 1, 0))
        lines.append(struct.pack("<ii", y, line_bytes) + data)
    return header + offsets + b"".join(lines)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else __file__.rsplit("/", 1)[0] + "/sky.exr"
    pixels = [radiance(direction((x + 0.5) / W, (y + 0.5) / H)) for y in range(H) for x in range(W)]
    tmp = out + ".tmp"
    with open(tmp, "wb") as f:
        f.write(exr(pixels, W, H))
    import os
    os.replace(tmp, out)
    print(f"{out}: {W} x {H}")


if __name__ == "__main__":
    main()
