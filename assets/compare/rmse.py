"""RMSE of images against two references of the same scene rendered with different seeds, with
the references' own noise taken out.

    python3 assets/compare/rmse.py REF_A.exr REF_B.exr IMAGE.exr [IMAGE.exr ...]

A reference's noise adds to every RMSE measured against it: MSE(image, ref) = MSE(image, truth)
+ noise(ref)^2 when the two are independent. The references' RMSE between them is sqrt(2) times
one's noise; their mean holds half one's noise squared, which is subtracted. Reads any EXR
Mitsuba reads (caustic's layered EXRs: the RGB of the unnamed layer).
"""
import sys
import numpy as np
import mitsuba as mi

mi.set_variant("scalar_rgb")


def rgb(path):
    """The image's RGB as float64, height x width x 3."""
    bitmap = mi.Bitmap(path)
    layers = dict(bitmap.split())
    for name in ("<root>", ""):
        if name in layers:
            bitmap = layers[name]
            break
    return np.array(bitmap, dtype=np.float64)[..., :3]


def rmse(x, y):
    return float(np.sqrt(np.mean((x - y) ** 2)))


if len(sys.argv) < 4:
    sys.exit("usage: rmse.py REF_A.exr REF_B.exr IMAGE.exr [IMAGE.exr ...]")
a, b = rgb(sys.argv[1]), rgb(sys.argv[2])
noise = rmse(a, b) / np.sqrt(2)
mean = 0.5 * (a + b)
print(f"references: RMSE between them {rmse(a, b):.4e}, each one's noise {noise:.4e}")
for path in sys.argv[3:]:
    x = rgb(path)
    against_mean = rmse(x, mean)
    alone = np.sqrt(max(against_mean**2 - noise**2 / 2, 0.0))
    print(f"{path}: RMSE against the first {rmse(x, a):.4e}, against their mean {against_mean:.4e}, "
          f"without the references' noise {alone:.4e} (image mean {x.mean():.5f})")
