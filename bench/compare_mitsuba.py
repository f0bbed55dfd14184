#!/usr/bin/env python3
"""marbre against Mitsuba 3 on the same scene: error against time.

The preset (by default the Cornell box of presets/cornell.ron) is built for
Mitsuba 3 from the same OBJ/MTL files: one mesh per material, Kd as a
diffuse reflectance, Ke as an area emitter on the front side; the same
camera, resolution, bounce limit and Russian roulette. Both renderers
render it at several sample counts, each against its own high-spp
reference (marbre through `marbre bench-convergence`), and the two
references are compared with each other: were they to disagree, the
renderers would not be computing the same image and the timings would
compare nothing ("comparison void", exit status 4).

Mitsuba is optional for marbre; this script needs it, and marbre built:

    pip install mitsuba numpy matplotlib   # --break-system-packages if pip refuses
    apt-get install -y libllvm19           # for the llvm_ad_rgb variant
    export DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1
    cargo build --release

    python3 bench/compare_mitsuba.py        # ~10 min on 2 idle cores, 6 of them
                                            # marbre's reference (then cached)
    python3 bench/compare_mitsuba.py --variant llvm_ad_rgb,scalar_rgb
    python3 bench/compare_mitsuba.py --kernel compute   # marbre's trace kernel
                                            # (default auto: decided by marbre's
                                            # first run, then kept for every row)
    python3 bench/compare_mitsuba.py --size 512x512 --reference-spp 4096 \\
        --spp 1,4,16,64,256                 # the full version (hours)

Timings are wall-clock seconds: on a shared machine other processes slow
both renderers, which is why the renders at each sample count are
interleaved and repeated (--repeats) and the fastest kept.

Written to --out: results.md (tables and the references' agreement),
results.csv (one row per render), agreement.csv (per material region),
error_vs_time.png (log RMSE against log seconds), each renderer's
reference as EXR and marbre's own CSV. marbre caches its reference in
target/marbre-references, so a second run skips it.

Exit status: 0 done; 3 Mitsuba (or the variant asked for) cannot be
loaded; 4 the references disagree (comparison void); 1 any other error.
"""
import argparse
import csv
import datetime
import importlib.util
import json
import math
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time

REPO = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
EXIT_NO_MITSUBA = 3
EXIT_VOID = 4

INSTALL_HINT = """This comparison needs Mitsuba 3, numpy and matplotlib, which marbre
itself does not; here they cannot be used ({cause}).
Install them with
    pip install mitsuba numpy matplotlib      (add --break-system-packages if pip refuses)
and, for the llvm_ad_rgb variant, an LLVM shared library (LLVM 15 does not work):
    apt-get install -y libllvm19
    export DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1
or run with --variant scalar_rgb, which needs no LLVM."""

# The agreement the references must show for the comparison to count.
MEAN_TOLERANCE = 0.01  # every region's mean and the image's, per channel: within 1 % of its brightness
NOISE_FACTOR = 1.5  # RMSE between the references ≤ 1.5 × what their own noise predicts


# ---------------------------------------------------------------- preset --

RON_TOKEN = re.compile(
    r"\s+|//[^\n]*|/\*.*?\*/"
    r'|(?P<str>"(?:[^"\\]|\\.)*")'
    r"|(?P<num>[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)"
    r"|(?P<id>[A-Za-z_]\w*)"
    r"|(?P<punct>[()\[\]:,])",
    re.S,
)


def parse_ron(text):
    """The subset of RON that presets use, as Python values: a struct is a
    dict, a tuple or list a list, `Name(x)` (an enum variant, `Some`) is
    {"Name": x}, and a bare identifier (a unit variant, `None`) a string,
    None, True or False."""
    tokens, pos = [], 0
    while pos < len(text):
        m = RON_TOKEN.match(text, pos)
        if not m:
            raise ValueError(f"preset: cannot read {text[pos:pos + 30]!r}")
        pos = m.end()
        if m.lastgroup:
            tokens.append(m.group(m.lastgroup))
    tokens.append(None)  # the end
    at = 0

    def take():
        nonlocal at
        at += 1
        return tokens[at - 1]

    def items(close):
        """Comma-separated values (or `name: value` fields) up to `close`."""
        fields, values = {}, []
        while tokens[at] != close:
            if tokens[at] is None:
                raise ValueError(f"preset: {close!r} missing at the end")
            if tokens[at + 1] == ":" and re.match(r"[A-Za-z_]", tokens[at]):
                name = take()
                take()
                fields[name] = value()
            else:
                values.append(value())
            if tokens[at] == ",":
                take()
            elif tokens[at] != close:
                raise ValueError(f"preset: expected ',' or {close!r}, found {tokens[at]!r}")
        take()
        return fields if fields else values

    def value():
        token = take()
        if token is None:
            raise ValueError("preset: unexpected end")
        if token in ("(", "["):
            return items(")" if token == "(" else "]")
        if token.startswith('"'):
            return json.loads(token)
        if re.match(r"[-+.\d]", token):
            return float(token)
        if re.match(r"[A-Za-z_]", token):
            if tokens[at] == "(":
                take()
                return {token: items(")")}
            return {"None": None, "true": True, "false": False}.get(token, token)
        raise ValueError(f"preset: unexpected {token!r}")

    return value()


def camera_frame(camera):
    """marbre's orbit camera (crates/core/src/scene/camera.rs) as a position, a forward,
    right and up vector and a vertical field of view."""
    target = camera.get("target", [0.0, 0.8, 0.0])
    distance = camera.get("distance", 9.0)
    yaw = math.radians(camera.get("yaw_degrees", 0.0))
    pitch = math.radians(min(max(camera.get("pitch_degrees", 15.0), -89.0), 89.0))
    # The camera sits on +z at yaw 0 and looks towards -z; pitch raises it.
    back = [math.cos(pitch) * math.sin(yaw), math.sin(pitch), math.cos(pitch) * math.cos(yaw)]
    right = [math.cos(yaw), 0.0, -math.sin(yaw)]
    forward = [-c for c in back]
    up = [
        right[1] * forward[2] - right[2] * forward[1],
        right[2] * forward[0] - right[0] * forward[2],
        right[0] * forward[1] - right[1] * forward[0],
    ]
    return {
        "position": [t + b * distance for t, b in zip(target, back)],
        "forward": forward,
        "right": right,
        "up": up,
        "fov": camera.get("fov_degrees", 40.0),
    }


def read_mtl(path):
    """Each material's Kd and Ke; refuses what marbre reads but this script
    does not translate (a specular lobe, textures, transparency)."""
    materials, name = {}, None
    for line in open(path):
        w = line.split("#")[0].split()
        if not w:
            continue
        if w[0] == "newmtl":
            name = w[1]
            materials[name] = {"Kd": [0.8] * 3, "Ke": [0.0] * 3}  # marbre's default Kd
        elif w[0] in ("Kd", "Ke"):
            materials[name][w[0]] = [float(x) for x in w[1:4]]
        elif (w[0] == "Ks" and any(float(x) for x in w[1:4])) or w[0].startswith("map_") or w[0] in ("d", "Tr", "Tf"):
            raise SystemExit(f"{path}: material {name}: `{line.strip()}` is not translated for Mitsuba")
    return materials


def read_obj(path, placement):
    """A mesh's triangles in the world, split by material: {material:
    (vertices, triangles)}, and its MTL materials. Polygons become fans from
    their first vertex, as marbre's loader (tobj) makes them."""
    vertices, faces, libraries, current = [], {}, [], None
    for line in open(path):
        w = line.split("#")[0].split()
        if not w:
            continue
        if w[0] == "v":
            vertices.append([float(x) for x in w[1:4]])
        elif w[0] == "mtllib":
            libraries += w[1:]
        elif w[0] == "usemtl":
            current = w[1]
        elif w[0] == "f":
            if current is None:
                raise SystemExit(f"{path}: a face before any `usemtl`: not translated for Mitsuba")
            idx = [int(c.split("/")[0]) for c in w[1:]]
            idx = [i - 1 if i > 0 else len(vertices) + i for i in idx]
            faces.setdefault(current, []).extend((idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1))
    materials = {}
    for library in libraries:
        materials.update(read_mtl(os.path.join(os.path.dirname(path), library)))
    # marbre's placement (crates/core/src/scene/mesh.rs): scaled, turned about +y, moved.
    scale = placement.get("scale", 1.0)
    angle = math.radians(placement.get("rotate_y_degrees", 0.0))
    move = placement.get("translate", [0.0, 0.0, 0.0])
    c, s = math.cos(angle), math.sin(angle)
    world = [
        [c * x * scale + s * z * scale + move[0], y * scale + move[1], -s * x * scale + c * z * scale + move[2]]
        for x, y, z in vertices
    ]
    return {mat: (world, tris) for mat, tris in faces.items()}, materials


def read_scene(preset_path):
    """What the comparison needs from a preset, refusing what it does not
    translate to Mitsuba rather than comparing different scenes."""
    scene = parse_ron(open(preset_path).read()).get("scene", {})
    refused = [key for key in ("spheres", "cylinders", "polygons") if scene.get(key)]
    refused += [key for key in ("ground", "point_light") if scene.get(key) is not None]
    if scene.get("environment", {}).get("source") is not None:
        refused.append("environment")
    render = scene.get("render", {})
    # Defaults as in crates/core/src/scene/render_settings.rs and crates/core/src/scene/transport.rs.
    transport = render.get("transport", {})
    if transport.get("integrator", "Path") != "Path":
        refused.append("integrator")
    if transport.get("strategy", "MisPower") != "MisPower":  # Mitsuba's path: MIS, power heuristic
        refused.append("strategy")
    if transport.get("light_samples", 1) != 1:  # Mitsuba's path: one emitter sample per vertex
        refused.append("light_samples")
    shapes = []
    for mesh in scene.get("meshes", []):
        if mesh.get("materials"):
            refused.append(f"mesh {mesh.get('name')}: edited materials")
            continue
        obj = os.path.join(os.path.dirname(preset_path), mesh["obj"])
        groups, materials = read_obj(obj, mesh.get("placement", {}))
        for mat, geometry in groups.items():
            if mat not in materials:
                raise SystemExit(f"{obj}: material {mat} is in no MTL file: not translated for Mitsuba")
            shapes.append((f"{mesh.get('name', 'mesh')}/{mat}", geometry, materials[mat]))
    if refused:
        raise SystemExit(f"{preset_path}: not translated for Mitsuba: {', '.join(refused)}")
    return {
        "camera": camera_frame(scene.get("camera", {})),
        "shapes": shapes,
        "max_bounces": int(render.get("max_bounces", 3)),
        "russian_roulette_from": int(transport.get("russian_roulette_from", 3)),
    }


# --------------------------------------------------------------- Mitsuba --


def mitsuba_scene(mi, setup, size, folder):
    """The scene as a Mitsuba dictionary; the meshes go through OBJ files
    written to `folder`, one per material, already triangulated."""
    width, height = size
    cam = setup["camera"]
    # How the two count path length. marbre's max_bounces B counts
    # reflections: it samples the lights at the first B surfaces the path
    # meets and adds the emission of the first B + 1 (shaders/trace.wgsl:
    # the loop stops at `bounces >= max_bounces` after adding emission).
    # Mitsuba's max_depth counts path segments from the camera (1: emitters
    # seen directly, 2: direct light): the same paths are max_depth = B + 1.
    # Russian roulette: marbre's `russian_roulette_from` R and Mitsuba's
    # rr_depth both count the bounces taken before the test, so rr_depth = R
    # (marbre's 0, never, becomes a depth no path reaches). Mitsuba caps the
    # survival chance at 0.95, marbre at 1: both are unbiased.
    rr_depth = setup["russian_roulette_from"] or setup["max_bounces"] + 2
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": setup["max_bounces"] + 1, "rr_depth": rr_depth},
        "sensor": {
            "type": "perspective",
            "fov_axis": "y",
            "fov": cam["fov"],
            "to_world": mi.ScalarTransform4f().look_at(
                origin=cam["position"],
                target=[p + f for p, f in zip(cam["position"], cam["forward"])],
                up=cam["up"],
            ),
            # marbre jitters its one ray per sample uniformly in the pixel: a box filter.
            "film": {"type": "hdrfilm", "width": width, "height": height, "rfilter": {"type": "box"}},
            "sampler": {"type": "independent"},
        },
    }
    for i, (name, (vertices, triangles), material) in enumerate(setup["shapes"]):
        path = os.path.join(folder, f"shape{i}.obj")
        with open(path, "w") as f:
            f.writelines(f"v {x} {y} {z}\n" for x, y, z in vertices)
            f.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in triangles)
        shape = {
            "type": "obj",
            "filename": path,
            "face_normals": True,
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": material["Kd"]}},
        }
        if any(material["Ke"]):
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": material["Ke"]}}
        scene[f"shape{i}"] = shape
    return scene


class MitsubaRenderer:
    """One Mitsuba variant and the scene loaded in it. Renders are split
    into passes of at most PASS_SAMPLES samples (the JIT variants hold a
    whole pass in memory), each with a seed of its own."""

    PASS_SAMPLES = 1 << 24

    def __init__(self, mi, np, variant, setup, size, folder):
        self.mi, self.np, self.variant, self.size = mi, np, variant, size
        mi.set_variant(variant)
        self.scene = mi.load_dict(mitsuba_scene(mi, setup, size, folder))
        self.next_seed = 0

    def render(self, spp):
        """The mean of `spp` samples per pixel, RGB, as a numpy array."""
        self.mi.set_variant(self.variant)  # the variants take turns
        width, height = self.size
        per_pass = max(1, self.PASS_SAMPLES // (width * height))
        total, done = 0.0, 0
        while done < spp:
            n = min(per_pass, spp - done)
            self.next_seed += 1
            # np.asarray waits for the result: the JIT variants are lazy.
            image = self.np.asarray(self.mi.render(self.scene, spp=n, seed=self.next_seed))[..., :3]
            total = total + image.astype(self.np.float64) * n
            done += n
        return total / spp

    def timed(self, spp):
        """A render and its seconds, after an untimed one: that compiles the
        kernels (as marbre's warm-up frame compiles its shader) and, when
        another variant or marbre ran in between, brings the JIT variant
        back up to speed (measured: 20× slower at 1 spp without it)."""
        self.render(spp)
        start = time.perf_counter()
        image = self.render(spp)
        return image, time.perf_counter() - start


def load_mitsuba(variants):
    """The mitsuba and numpy modules, every variant asked for and matplotlib
    checked (before a long run, not after); exits with EXIT_NO_MITSUBA and
    how to install them otherwise."""
    try:
        import drjit as dr
        import mitsuba as mi
        import numpy as np

        if importlib.util.find_spec("matplotlib") is None:  # for the plot, at the end
            raise ImportError("No module named 'matplotlib'")
    except ImportError as e:
        print(INSTALL_HINT.format(cause=e), file=sys.stderr)
        sys.exit(EXIT_NO_MITSUBA)
    for variant in variants:
        try:
            mi.set_variant(variant)
            if not variant.startswith("scalar"):
                np.asarray(dr.arange(mi.Float, 4))  # a JIT variant finds its backend (LLVM) here
        except Exception as e:  # an unknown variant or no LLVM: Mitsuba raises several kinds
            print(INSTALL_HINT.format(cause=f"variant {variant}: {e}"), file=sys.stderr)
            sys.exit(EXIT_NO_MITSUBA)
    return mi, np


# ---------------------------------------------------------------- marbre --


def run_marbre(args, spp):
    """`marbre bench-convergence` on the preset at one sample count: its row
    (spp, seconds, samples/s, rmse), its reference (rendered the first
    time, then cached) and what it printed."""
    csv_path = os.path.join(args.out, "marbre.csv")
    reference_path = os.path.join(args.out, "marbre-reference.exr")
    command = [
        args.marbre, "bench-convergence",
        "--preset", args.preset,
        "--size", f"{args.size[0]}x{args.size[1]}",
        "--reference-spp", str(args.reference_spp),
        "--spp", str(spp),
        "--csv", csv_path,
        "--reference-out", reference_path,
        # `auto` is decided by marbre's first run and then kept, so that every
        # row of marbre's is the same kernel.
        "--kernel", args.kernel_used.split(" ")[0] if args.kernel_used else args.kernel,
    ]
    # From the repository root: the reference cache is target/marbre-references there.
    result = subprocess.run(command, cwd=REPO, stdout=subprocess.PIPE, text=True)
    if result.returncode != 0:
        print("$", " ".join(command), "\n" + result.stdout, file=sys.stderr)
        raise SystemExit(f"marbre bench-convergence failed (exit status {result.returncode})")
    with open(csv_path) as f:
        (row,) = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
    return row, reference_path, result.stdout


# --------------------------------------------------------------- measure --


def measure(args, mi, np, setup, folder):
    """Mitsuba's references, then --repeats rounds of every timed render:
    at each spp marbre's and then each Mitsuba variant's, so that renders
    compared with each other meet about the same background load. Of each
    renderer's renders at one spp the fastest is kept (marbre's sample
    sequence is fixed: its repeats are the same image). Returns {renderer:
    rows}, Mitsuba's references, the path of marbre's, marbre's adapter and
    its name among the renderers."""
    width, height = args.size
    renderers, references, fastest = {}, {}, {}

    def keep(renderer, row):
        rows = fastest.setdefault(renderer, {})
        if row["spp"] not in rows or row["seconds"] < rows[row["spp"]]["seconds"]:
            rows[row["spp"]] = row

    for variant in args.variant.split(","):
        print(f"mitsuba {mi.__version__} {variant}: reference, {args.reference_spp} spp", flush=True)
        renderers[variant] = MitsubaRenderer(mi, np, variant, setup, args.size, folder)
        start = time.perf_counter()
        references[variant] = renderers[variant].render(args.reference_spp)
        print(f"  in {time.perf_counter() - start:.1f} s", flush=True)
        path = os.path.join(args.out, f"mitsuba-{variant}-reference.exr")
        mi.util.write_bitmap(path, references[variant].astype(np.float32))
    for n in range(1, args.repeats + 1):
        print(f"round {n} of {args.repeats}", flush=True)
        for spp in args.spp:
            first = n == 1 and spp == args.spp[0]
            if first:
                print(f"marbre: its reference, {args.reference_spp} spp, unless cached (minutes)", flush=True)
            row, marbre_reference, log = run_marbre(args, spp)
            if first:
                print(log, end="", flush=True)
            adapter = next((line[len("adapter: "):] for line in log.splitlines() if line.startswith("adapter: ")), "?")
            if args.kernel_used is None:
                # "kernel: compute", or "kernel: compute (auto: fragment ... ms, compute ... ms per frame at WxH)"
                args.kernel_used = next(
                    (line[len("kernel: "):] for line in log.splitlines() if line.startswith("kernel: ")), None
                )
                if args.kernel_used is None:
                    raise SystemExit(f"{args.marbre} printed no `kernel:` line: a build without --kernel?")
            marbre = f"marbre ({adapter.split(' (')[0]}, {args.kernel_used.split(' ')[0]} kernel)"
            keep(marbre, row)
            print(f"  marbre, {spp} spp: {row['seconds']:.3f} s, RMSE {row['rmse']:.5f}", flush=True)
            for variant, renderer in renderers.items():
                image, seconds = renderer.timed(spp)
                rmse = float(np.sqrt(np.mean((image - references[variant]) ** 2)))
                keep(f"Mitsuba {variant}", {"spp": spp, "seconds": seconds, "samples_per_second": width * height * spp / seconds, "rmse": rmse})
                print(f"  Mitsuba {variant}, {spp} spp: {seconds:.3f} s, RMSE {rmse:.5f}", flush=True)
    results = {renderer: list(rows.values()) for renderer, rows in fastest.items()}
    return results, references, marbre_reference, adapter, marbre


# ------------------------------------------------------------- agreement --


def material_regions(np, setup, size):
    """Which material each pixel sees, by casting marbre's camera rays
    (shaders/trace.wgsl: camera_ray) through the pixel's centre and four
    points near its corners against the triangles: -1 where they disagree
    (an edge) or miss."""
    width, height = size
    cam = {k: np.array(v, dtype=np.float64) for k, v in setup["camera"].items() if k != "fov"}
    tan_half = math.tan(math.radians(setup["camera"]["fov"]) / 2)
    triangles, labels = [], []
    for label, (_, (vertices, tris), _) in enumerate(setup["shapes"]):
        v = np.array(vertices, dtype=np.float64)
        triangles += [v[list(t)] for t in tris]
        labels += [label] * len(tris)
    ys, xs = np.mgrid[0:height, 0:width].astype(np.float64)
    region = None
    for dx, dy in [(0.5, 0.5), (0.02, 0.02), (0.98, 0.02), (0.02, 0.98), (0.98, 0.98)]:
        x = ((xs + dx) / width * 2 - 1) * tan_half * width / height
        y = (1 - (ys + dy) / height * 2) * tan_half
        d = cam["forward"] + x[..., None] * cam["right"] + y[..., None] * cam["up"]
        d /= np.linalg.norm(d, axis=-1, keepdims=True)
        nearest = np.full((height, width), np.inf)
        seen = np.full((height, width), -1)
        # Möller–Trumbore, one triangle at a time over every pixel.
        for (p0, p1, p2), label in zip(triangles, labels):
            e1, e2, s = p1 - p0, p2 - p0, cam["position"] - p0
            p = np.cross(d, e2)
            det = p @ e1
            with np.errstate(divide="ignore", invalid="ignore"):
                u = (p @ s) / det
                q = np.cross(s, e1)
                v = (d @ q) / det
                t = (q @ e2) / det
            hit = (np.abs(det) > 1e-12) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-6) & (t < nearest)
            nearest[hit], seen[hit] = t[hit], label
        region = seen if region is None else np.where(region == seen, region, -1)
    return region


def mean_difference(a, b):
    """The largest difference between two RGB means, relative to their
    brightness (the mean over channels): a dim channel (the red wall's
    blue) is judged on the region's scale, where its noise is small."""
    return max(abs(x - y) for x, y in zip(a, b)) / ((sum(a) + sum(b)) / 6)


def compare_references(np, setup, marbre_ref, mitsuba_ref, regions, noise):
    """The references' agreement: per region and image means per channel,
    the RMSE between them against the bound from their own noise."""
    rows = []
    for label, (name, _, _) in enumerate(setup["shapes"]):
        mask = regions == label
        if mask.any():
            rows.append((name, int(mask.sum()), marbre_ref[mask].mean(axis=0), mitsuba_ref[mask].mean(axis=0)))
    rows.append(("whole image", regions.size, marbre_ref.reshape(-1, 3).mean(axis=0), mitsuba_ref.reshape(-1, 3).mean(axis=0)))
    rmse = float(np.sqrt(np.mean((marbre_ref - mitsuba_ref) ** 2)))
    # Independent references of own noise a and b differ by √(a² + b²) RMS.
    expected = math.hypot(*noise)
    worst = max(mean_difference(a, b) for _, _, a, b in rows)
    return {
        "rows": rows,
        "rmse": rmse,
        "expected": expected,
        "bound": NOISE_FACTOR * expected,
        "worst_mean": worst,
        "agree": worst <= MEAN_TOLERANCE and rmse <= NOISE_FACTOR * expected,
    }


def reference_noise(rows, reference_spp):
    """A reference's own RMSE, from the measured render with the most
    samples: against an independent N-spp reference an n-spp render's RMSE
    is σ·√(1/n + 1/N), so σ follows, and the reference's noise is σ/√N."""
    last = max(rows, key=lambda r: r["spp"])
    sigma = last["rmse"] / math.sqrt(1 / last["spp"] + 1 / reference_spp)
    return sigma / math.sqrt(reference_spp)


# --------------------------------------------------------------- outputs --


def cpu_name():
    try:
        with open("/proc/cpuinfo") as f:
            names = [line.split(":", 1)[1].strip() for line in f if line.startswith("model name")]
        return f"{names[0]} ({len(names)} logical cores)" if names else platform.processor()
    except OSError:
        return platform.processor()


def write_plot(results, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for renderer, rows in results.items():
        seconds = [r["seconds"] for r in rows]
        rmse = [r["rmse"] for r in rows]
        ax.loglog(seconds, rmse, "o-", label=renderer)
        for r in rows:
            ax.annotate(f"{int(r['spp'])}", (r["seconds"], r["rmse"]), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.set_xlabel("seconds (render time)")
    ax.set_ylabel("RMSE against the renderer's own reference")
    ax.set_title("Error against time (labels: samples per pixel)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def markdown(results, efficiency, marbre, agreements, header):
    lines = header + [
        "",
        "| renderer | spp | seconds | samples/s | RMSE | RMSE × √seconds |",
        "|---|---|---|---|---|---|",
    ]
    for renderer, rows in results.items():
        for r in rows:
            lines.append(
                f"| {renderer} | {int(r['spp'])} | {r['seconds']:.3f} | {r['samples_per_second'] / 1e6:.3f} M "
                f"| {r['rmse']:.5f} | {r['rmse'] * math.sqrt(r['seconds']):.5f} |"
            )
    fastest = min(efficiency, key=efficiency.get)
    lines += [
        "",
        f"| renderer | RMSE × √seconds (median of the rows) | time to RMSE 0.01 | time at equal RMSE vs {fastest} |",
        "|---|---|---|---|",
    ]
    for renderer, e in efficiency.items():
        lines.append(f"| {renderer} | {e:.4f} | {(e / 0.01) ** 2:.1f} s | {(e / efficiency[fastest]) ** 2:.1f}× |")
    lines.append("")
    lines += [
        f"At equal RMSE marbre needs {(efficiency[marbre] / e) ** 2:.1f}× {renderer}'s time."
        for renderer, e in efficiency.items()
        if renderer != marbre
    ]
    for variant, a in agreements.items():
        lines += [
            "",
            f"References: marbre against Mitsuba {variant} (means per channel R, G, B; "
            "regions: pixels that see one material only)",
            "",
            "| region | pixels | marbre mean | Mitsuba mean | largest channel difference / brightness |",
            "|---|---|---|---|---|",
        ]
        for name, pixels, m, k in a["rows"]:
            lines.append(
                f"| {name} | {pixels} | {' '.join(f'{c:.4f}' for c in m)} | {' '.join(f'{c:.4f}' for c in k)} "
                f"| {100 * mean_difference(m, k):.3f} % |"
            )
        lines += [
            "",
            f"RMSE between the references {a['rmse']:.5f}; their own noise predicts {a['expected']:.5f} "
            f"(bound {NOISE_FACTOR} × that = {a['bound']:.5f}); worst mean difference {100 * a['worst_mean']:.3f} % "
            f"(tolerance {100 * MEAN_TOLERANCE:.0f} %): **{'agree' if a['agree'] else 'comparison void'}**.",
        ]
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------ main --


def parse_size(text):
    m = re.fullmatch(r"(\d+)(?:x(\d+))?", text)
    if not m:
        raise argparse.ArgumentTypeError(f"{text!r}: expected WxH or N")
    return int(m.group(1)), int(m.group(2) or m.group(1))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--preset", default="presets/cornell.ron", help="marbre preset, relative to the repository (default: %(default)s)")
    p.add_argument("--size", type=parse_size, default=(256, 256), help="WxH, or N for NxN (default: 256x256)")
    p.add_argument("--spp", type=lambda s: [int(x) for x in s.split(",")], default=[1, 4, 16, 64], help="samples per pixel measured, comma-separated (default: 1,4,16,64)")
    p.add_argument("--reference-spp", type=int, default=1024, help="samples per pixel of both references (default: %(default)s)")
    p.add_argument("--repeats", type=int, default=3, help="rounds of timed renders, marbre's and Mitsuba's in turn; the fastest of each is kept (default: %(default)s)")
    p.add_argument("--variant", default="llvm_ad_rgb", help="Mitsuba variants, comma-separated: llvm_ad_rgb, scalar_rgb (default: %(default)s)")
    default_marbre = os.path.join(os.environ.get("CARGO_TARGET_DIR", os.path.join(REPO, "target")), "release", "marbre")
    p.add_argument("--marbre", default=default_marbre, help="the marbre binary (default: $CARGO_TARGET_DIR or target, then release/marbre)")
    p.add_argument("--kernel", choices=["fragment", "compute", "cpu", "auto"], default="auto",
                   help="marbre's trace kernel, passed to `marbre bench-convergence --kernel` (default: %(default)s: "
                   "the faster of the two on the preset, timed by marbre first)")
    p.add_argument("--out", default=os.path.join(REPO, "target", "compare-mitsuba"), help="output folder (default: target/compare-mitsuba)")
    args = p.parse_args()
    args.kernel_used = None  # the kernel marbre's first run traced with, as it printed it
    args.preset = os.path.join(REPO, args.preset) if not os.path.isabs(args.preset) else args.preset
    args.marbre = os.path.abspath(args.marbre)
    variants = args.variant.split(",")
    if not all(v.endswith("_rgb") for v in variants):
        p.error("--variant: RGB variants only (llvm_ad_rgb, scalar_rgb): marbre renders RGB")

    mi, np = load_mitsuba(variants)
    if not os.access(args.marbre, os.X_OK):
        raise SystemExit(f"{args.marbre}: no marbre binary (cargo build --release, or --marbre PATH)")
    setup = read_scene(args.preset)
    os.makedirs(args.out, exist_ok=True)
    width, height = args.size
    load_before = os.getloadavg()
    started = datetime.datetime.now()
    with tempfile.TemporaryDirectory() as folder:
        results, references, marbre_reference_path, adapter, marbre = measure(args, mi, np, setup, folder)
    load_after = os.getloadavg()

    # Each reference's own noise, from its renderer's rows.
    noise = {renderer: reference_noise(rows, args.reference_spp) for renderer, rows in results.items()}
    marbre_ref = np.asarray(mi.Bitmap(marbre_reference_path), dtype=np.float64)[..., :3]
    regions = material_regions(np, setup, args.size)
    agreements = {
        v: compare_references(np, setup, marbre_ref, references[v], regions, (noise[marbre], noise[f"Mitsuba {v}"]))
        for v in variants
    }

    # RMSE falls as 1/√time, so RMSE·√t is one constant per renderer, which
    # predicts the time to any error, t(E) = (RMSE·√t / E)²; two renderers'
    # times at equal error are in the ratio of its squares. Each row
    # estimates it; their median resists a row timed under a burst of load.
    efficiency = {
        renderer: statistics.median(r["rmse"] * math.sqrt(r["seconds"]) for r in rows)
        for renderer, rows in results.items()
    }
    llvm = ""
    if any(v.startswith("llvm") for v in variants):
        import drjit as dr

        llvm = f", LLVM {'.'.join(map(str, dr.detail.llvm_version()))}"
    header = [
        f"# marbre against Mitsuba {mi.__version__} ({started:%Y-%m-%d %H:%M})",
        "",
        f"{os.path.relpath(args.preset, REPO)}: {width}×{height}, marbre max_bounces {setup['max_bounces']} = Mitsuba "
        f"max_depth {setup['max_bounces'] + 1}, Russian roulette from bounce {setup['russian_roulette_from']}; "
        f"references {args.reference_spp} spp, each renderer against its own.",
        f"CPU: {cpu_name()}; marbre adapter: {adapter}; marbre kernel: {args.kernel_used} (--kernel {args.kernel}); "
        f"Mitsuba variants: {', '.join(variants)}{llvm}.",
        f"Load average before {load_before[0]:.2f}, after {load_after[0]:.2f}: timings are noisy where other "
        "processes share the CPU.",
    ]
    with open(os.path.join(args.out, "results.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["renderer", "spp", "seconds", "samples_per_second", "rmse", "rmse_sqrt_seconds"])
        for renderer, rows in results.items():
            for r in rows:
                w.writerow([renderer, int(r["spp"]), r["seconds"], r["samples_per_second"], r["rmse"], r["rmse"] * math.sqrt(r["seconds"])])
    with open(os.path.join(args.out, "agreement.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["variant", "region", "pixels", "marbre_r", "marbre_g", "marbre_b", "mitsuba_r", "mitsuba_g", "mitsuba_b"])
        for variant, a in agreements.items():
            for name, pixels, m, k in a["rows"]:
                w.writerow([variant, name, pixels, *m, *k])
    report = markdown(results, efficiency, marbre, agreements, header)
    with open(os.path.join(args.out, "results.md"), "w") as f:
        f.write(report)
    write_plot(results, os.path.join(args.out, "error_vs_time.png"))
    print()
    print(report)
    print(f"written to {args.out}: results.md, results.csv, agreement.csv, error_vs_time.png, references (EXR)")
    if not all(a["agree"] for a in agreements.values()):
        print("comparison void: the references disagree beyond the tolerance; the timings compare different images", file=sys.stderr)
        sys.exit(EXIT_VOID)


if __name__ == "__main__":
    main()
