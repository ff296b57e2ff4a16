"""assets/compare/cornell_rough.toml or cornell_smooth.toml in Mitsuba 3's path tracer
(llvm_ad_rgb), for comparing caustic's renderers with an independent implementation of the same
materials: rough (GGX `roughdielectric` and `roughconductor` with `material = "none"`) or smooth
(`dielectric` and `conductor` with `material = "none"`).

    pip install mitsuba          # and Debian's libllvm19 for the llvm variant
    python3 assets/compare/mitsuba_cornell.py rough|smooth SPP OUT.exr [SEED]

A reference's own noise adds to every RMSE measured against it: render two with different
seeds and their RMSE is sqrt(2) times one's noise (see README, "Against Mitsuba 3").
"""
import sys, time
import mitsuba as mi
mi.set_variant("llvm_ad_rgb")
T = mi.ScalarTransform4f
def rect(center, rot_axis, rot_deg, bsdf, emitter=None):
    t = T().translate(center).rotate(rot_axis, rot_deg)
    d = {"type": "rectangle", "to_world": t, "bsdf": bsdf}
    if emitter: d["emitter"] = emitter
    return d
diffuse = lambda c: {"type": "diffuse", "reflectance": {"type": "rgb", "value": c}}
grey, red, green = diffuse([0.75]*3), diffuse([0.75, 0.25, 0.25]), diffuse([0.25, 0.75, 0.25])
if len(sys.argv) not in (4, 5) or sys.argv[1] not in ("rough", "smooth"):
    sys.exit("usage: mitsuba_cornell.py rough|smooth SPP OUT.exr [SEED]")
smooth = sys.argv[1] == "smooth"
spp = int(sys.argv[2])
seed = int(sys.argv[4]) if len(sys.argv) == 5 else 0
glass = ({"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0} if smooth else
         {"type": "roughdielectric", "distribution": "ggx", "alpha": 0.1, "int_ior": 1.5, "ext_ior": 1.0})
mirror = ({"type": "conductor", "material": "none"} if smooth else
          {"type": "roughconductor", "material": "none", "distribution": "ggx", "alpha": 0.2})
scene = mi.load_dict({
    "type": "scene",
    "integrator": {"type": "path", "max_depth": 65},
    "sensor": {"type": "perspective", "fov": 39.3, "fov_axis": "y",
               "to_world": T().look_at(origin=[0, 0, 3.9], target=[0, 0, 0], up=[0, 1, 0]),
               "film": {"type": "hdrfilm", "width": 256, "height": 256, "rfilter": {"type": "box"}},
               "sampler": {"type": "independent", "sample_count": spp}},
    # Rectangles span [-1,1]^2 in xy with normal +z before the transform.
    "floor": rect([0, -1, 0], [1, 0, 0], -90, grey),
    "ceiling": rect([0, 1, 0], [1, 0, 0], 90, grey),
    "back": rect([0, 0, -1], [0, 1, 0], 0, grey),
    "left": rect([-1, 0, 0], [0, 1, 0], 90, red),
    "right": rect([1, 0, 0], [0, 1, 0], -90, green),
    "light": {"type": "rectangle",
              "to_world": T().translate([0, 0.99, 0]).rotate([1, 0, 0], 90).scale([0.25, 0.25, 1]),
              "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0, 0, 0]}},
              "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [12, 12, 12]}}},
    "glass": {"type": "sphere", "center": [0.45, -0.65, 0.30], "radius": 0.35, "bsdf": glass},
    "mirror": {"type": "sphere", "center": [-0.45, -0.65, -0.35], "radius": 0.35, "bsdf": mirror},
})
t = time.time()
img = mi.render(scene, spp=spp, seed=seed)
mi.Bitmap(img).write(sys.argv[3])
print(f"{spp} spp in {time.time() - t:.1f} s")
