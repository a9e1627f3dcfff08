#!/usr/bin/env python3
"""Writes many-emitters.xml: the unit square light of degenerate-emitter.xml (height 0.5,
facing down, radiance 1) cut into N x N tiles, each its own emitter (issue 6: thousands of
emitters). The receiver sees the same square, so its radiance is that of the uncut light;
uniform emitter choice picks each tile with probability 1 / N^2.

Each tile is Mitsuba's rectangle ([-1, 1]^2, normal +z) under the matrix
diag(s, -s, -1) + translation: the y and z flips keep the determinant positive (no mirror
warning) and turn the normal and the winding to -z. Tile centres and half-sides are exact
binary fractions, so the vertices are exact in f32.

Usage: python3 make_many_emitters.py [N]   (default 64: 4096 emitters)
"""
import os
import sys

n = int(sys.argv[1]) if len(sys.argv) > 1 else 64
s = 0.5 / n  # half-side of a tile
here = os.path.dirname(os.path.abspath(__file__))

head = f"""<?xml version="1.0" encoding="utf-8"?>
<!--
  Written by make_many_emitters.py (N = {n}): a unit square light at height 0.5, facing down,
  radiance 1, cut into {n} x {n} = {n * n} tiles, each its own emitter, over a diffuse floor
  (albedo 0.5) seen at the origin from (0, 0, 0.25) by a one-pixel camera. The receiver's
  radiance is that of the uncut square (Lambert: 0.5 / pi * 1.740840 = 0.277063), whatever the
  emitter choice.
-->
<scene version="3.0.0">
    <integrator type="direct"/>

    <sensor type="perspective">
        <float name="fov" value="0.001"/>
        <float name="near_clip" value="0.0001"/>
        <float name="far_clip" value="1000000"/>
        <transform name="to_world">
            <lookat origin="0, 0, 0.25" target="0, 0, 0" up="0, 1, 0"/>
        </transform>
        <film type="hdrfilm">
            <integer name="width" value="1"/>
            <integer name="height" value="1"/>
            <rfilter type="box"/>
        </film>
    </sensor>

    <bsdf type="diffuse" id="black">
        <rgb name="reflectance" value="0"/>
    </bsdf>

    <shape type="rectangle">
        <bsdf type="diffuse">
            <rgb name="reflectance" value="0.5"/>
        </bsdf>
    </shape>

    <!-- The tiles: rectangle under [s 0 0 x; 0 -s 0 y; 0 0 -1 0.5], radiance 1 (the default). -->
"""
rows = []
for j in range(n):
    for i in range(n):
        x = -0.5 + (2 * i + 1) * s
        y = -0.5 + (2 * j + 1) * s
        m = f"{s!r} 0 0 {x!r} 0 {-s!r} 0 {y!r} 0 0 -1 0.5 0 0 0 1"
        rows.append(
            f'    <shape type="rectangle"><transform name="to_world"><matrix value="{m}"/>'
            f'</transform><ref id="black"/><emitter type="area"/></shape>'
        )
with open(os.path.join(here, "many-emitters.xml"), "w") as f:
    f.write(head + "\n".join(rows) + "\n</scene>\n")
