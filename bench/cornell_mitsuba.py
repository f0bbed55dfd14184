#!/usr/bin/env python3
"""The Cornell box of presets/cornell.ron rendered by Mitsuba 3, for timing
marbre against a peer on the same scene: the same OBJ/MTL (one mesh per
material: Kd as a diffuse reflectance, Ke as an area emitter on the front
side), the same camera, resolution and bounce limit.

    pip install mitsuba numpy   # the llvm_ad_rgb variant needs an LLVM shared
                             # library: DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 (Debian: apt install libllvm19)
    python3 bench/cornell_mitsuba.py --variant llvm_ad_rgb --size 256 --spp 1,4,16,64 --reference-spp 1024

It prints samples per second and the RMSE of each render against
Mitsuba's own high-spp reference, and writes that reference as EXR
(--reference-out) so it can be compared with marbre's.
"""
import argparse
import os
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "..", "presets", "scenes", "cornell-box", "CornellBox-Original.obj")


def split_by_material(obj_path, folder):
    """One OBJ file per `usemtl` group, and each material's Kd and Ke."""
    vertices, groups, current = [], {}, None
    for line in open(obj_path):
        w = line.split("#")[0].split()
        if not w:
            continue
        if w[0] == "v":
            vertices.append(w[1:4])
        elif w[0] == "usemtl":
            current = w[1]
            groups.setdefault(current, [])
        elif w[0] == "f":
            idx = [int(c.split("/")[0]) for c in w[1:]]
            idx = [i if i > 0 else len(vertices) + 1 + i for i in idx]
            groups[current].append(idx)
    materials, name = {}, None
    for line in open(os.path.join(os.path.dirname(obj_path), "CornellBox-Original.mtl")):
        w = line.split("#")[0].split()
        if not w:
            continue
        if w[0] == "newmtl":
            name = w[1]
            materials[name] = {"Kd": [0.0] * 3, "Ke": [0.0] * 3}
        elif w[0] in ("Kd", "Ke"):
            materials[name][w[0]] = [float(x) for x in w[1:4]]
    files = {}
    for mat, faces in groups.items():
        path = os.path.join(folder, f"{mat}.obj")
        with open(path, "w") as f:
            for v in vertices:
                f.write("v " + " ".join(v) + "\n")
            for face in faces:
                f.write("f " + " ".join(str(i) for i in face) + "\n")
        files[mat] = path
    return files, materials


def scene_dict(mi, size, max_bounces, folder):
    files, materials = split_by_material(SCENE, folder)
    scene = {
        "type": "scene",
        # marbre's max bounces counts reflections; Mitsuba's max_depth counts
        # path segments from the camera (2 = direct light only).
        "integrator": {"type": "path", "max_depth": max_bounces + 1, "rr_depth": 3},
        "sensor": {
            "type": "perspective",
            "fov_axis": "y",
            "fov": 39.3,
            "to_world": mi.ScalarTransform4f().look_at(origin=[0, 1, 3.9], target=[0, 1, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"}},
            "sampler": {"type": "independent"},
        },
    }
    for mat, path in files.items():
        m = materials[mat]
        shape = {
            "type": "obj",
            "filename": path,
            "face_normals": True,
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": m["Kd"]}},
        }
        if any(m["Ke"]):
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": m["Ke"]}}
        scene[mat] = shape
    return scene


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--variant", default="llvm_ad_rgb")
    p.add_argument("--size", type=int, default=256)
    p.add_argument("--max-bounces", type=int, default=8)
    p.add_argument("--spp", default="1,4,16,64")
    p.add_argument("--reference-spp", type=int, default=1024)
    p.add_argument("--reference-out", default=None)
    args = p.parse_args()
    try:
        import mitsuba as mi
        import numpy as np
    except ImportError:
        sys.exit("Mitsuba is optional: pip install mitsuba numpy (see this script's header)")
    mi.set_variant(args.variant)
    with tempfile.TemporaryDirectory() as folder:
        scene = mi.load_dict(scene_dict(mi, args.size, args.max_bounces, folder))

        def render(spp, seed):
            image = mi.render(scene, spp=spp, seed=seed)
            np.asarray(image)  # waits for the result (JIT variants are lazy)
            start = time.perf_counter()
            image = np.asarray(mi.render(scene, spp=spp, seed=seed + 1))
            return image, time.perf_counter() - start

        reference, seconds = render(args.reference_spp, 1000)
        print(f"mitsuba {mi.__version__} {args.variant}: {args.size}x{args.size}, max_depth {args.max_bounces + 1}")
        print(f"reference: {args.reference_spp} spp in {seconds:.1f} s")
        if args.reference_out:
            mi.util.write_bitmap(args.reference_out, reference)
        print("| spp | seconds | samples/s | RMSE | RMSE × √seconds |")
        print("|---|---|---|---|---|")
        for spp in [int(s) for s in args.spp.split(",")]:
            image, seconds = render(spp, spp)
            rmse = float(np.sqrt(np.mean((image[..., :3] - reference[..., :3]) ** 2)))
            rate = args.size * args.size * spp / seconds
            print(f"| {spp} | {seconds:.3f} | {rate / 1e6:.3f} M | {rmse:.5f} | {rmse * seconds ** 0.5:.5f} |")


if __name__ == "__main__":
    main()
