#!/usr/bin/env python3
# Writes the small environment images of the environment-map analytic scenes
# as uncompressed Radiance RGBE (.hdr), with values that RGBE holds exactly
# (a mantissa of 8 bits times a power of two shared by the three channels).
# Run from this folder: python3 make_envmaps.py
import math


def rgbe(r, g, b):
    m = max(r, g, b)
    if m <= 0.0:
        return bytes([0, 0, 0, 0])
    frac, e = math.frexp(m)  # m = frac * 2^e, frac in [0.5, 1)
    scale = 256.0 / 2.0**e
    mant = [int(v * scale) for v in (r, g, b)]
    for v, q in zip((r, g, b), mant):
        assert q / scale == v, f"{v} is not exact in RGBE"
    return bytes(mant + [e + 128])


def write_hdr(name, width, height, texel):
    with open(name, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
        f.write(f"-Y {height} +X {width}\n".encode())
        for y in range(height):  # row 0 first: the top of the image, +y
            for x in range(width):
                f.write(rgbe(*texel(x, y)))


# A constant map of the radiance sphere-in-environment.json gives as a colour.
write_hdr("constant-8x4.hdr", 8, 4, lambda x, y: (2.0, 1.0, 0.5))


# 16 x 8 texels with structure in both directions: red grows with the column,
# green with the row, blue alternates, and one bright texel (a small "sun",
# column 5, row 2) that light sampling has to find.
def structured(x, y):
    if (x, y) == (5, 2):
        return (8.0, 6.0, 4.0)
    return ((x + 1) / 16.0, (y + 1) / 8.0, 0.25 if (x + y) % 2 else 0.75)


write_hdr("structured-16x8.hdr", 16, 8, structured)
