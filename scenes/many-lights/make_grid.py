#!/usr/bin/env python3
"""Writes grid.xml: N x N small square lights in the plane z = H, facing down, over a diffuse
floor (issue 46: many-light emitter choice). Lights in one plane facing down cannot shadow one
another for a point below them, so a floor point's radiance is exactly albedo / pi times the
sum of Lambert's formula over the lights (`directlab`'s tests check renders against it).

The lights are far apart compared with their height, so a floor point sees mostly its
neighbours: a choice that knows the shading point (a light tree) beats power-proportional
choice by a wide margin. Radiances vary over two orders of magnitude in a fixed pattern, so
power and uniform choice differ too.

Each light is Mitsuba's rectangle ([-1, 1]^2, normal +z) under diag(s, -s, -1) + translation:
the y and z flips keep the determinant positive and turn the normal to -z. Centres and the
half-side are exact binary fractions.

Usage: python3 make_grid.py [N]   (default 48: 2304 lights)
"""
import os
import sys

n = int(sys.argv[1]) if len(sys.argv) > 1 else 48
pitch = 0.25
half = 0.015625
height = 0.25
here = os.path.dirname(os.path.abspath(__file__))


def radiance(i, j):
    # A fixed pattern over two orders of magnitude (no randomness: the file is reproducible).
    k = ((i * 7 + j * 13) % 17) / 16.0
    return 8.0 + 640.0 * k**3


head = f"""<?xml version="1.0" encoding="utf-8"?>
<!--
  Written by make_grid.py (N = {n}): {n} x {n} = {n * n} square lights (half-side {half}, pitch
  {pitch}) at height {height}, facing down, radiances 8 to 648, over a diffuse floor
  (albedo 0.5). Every light is its own emitter.
-->
<scene version="3.0.0">
    <default name="width" value="96"/>
    <default name="height" value="64"/>
    <default name="spp" value="16"/>
    <integrator type="direct"/>

    <sensor type="perspective">
        <float name="fov" value="60"/>
        <transform name="to_world">
            <lookat origin="0, 0, 8" target="0, 0, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="independent">
            <integer name="sample_count" value="$spp"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="$width"/>
            <integer name="height" value="$height"/>
        </film>
    </sensor>

    <bsdf type="diffuse" id="black">
        <rgb name="reflectance" value="0"/>
    </bsdf>

    <shape type="rectangle">
        <transform name="to_world">
            <scale value="10"/>
        </transform>
        <bsdf type="diffuse">
            <rgb name="reflectance" value="0.5"/>
        </bsdf>
    </shape>

    <!-- The lights: rectangle under [s 0 0 x; 0 -s 0 y; 0 0 -1 H]. -->
"""
rows = []
start = -0.5 * pitch * (n - 1)
for j in range(n):
    for i in range(n):
        x = start + pitch * i
        y = start + pitch * j
        m = f"{half!r} 0 0 {x!r} 0 {-half!r} 0 {y!r} 0 0 -1 {height!r} 0 0 0 1"
        rows.append(
            f'    <shape type="rectangle"><transform name="to_world"><matrix value="{m}"/>'
            f'</transform><ref id="black"/><emitter type="area">'
            f'<rgb name="radiance" value="{radiance(i, j)!r}"/></emitter></shape>'
        )
with open(os.path.join(here, "grid.xml"), "w") as f:
    f.write(head + "\n".join(rows) + "\n</scene>\n")
