#!/usr/bin/python3
"""Pictures and render time: `leaflux render` on the 119k tree lit by HRC and by the
instanced solver (one colour scale for both), on a plantation (also in true colour from its
R, G, B bands, with a scale bar and a north arrow) and inside the greenhouse at night. Each scene is solved once (`leaflux solve --out`), then drawn from that CSV
(`render --from`), so the time is the picture's alone: primary rays, colours, colour bar.
Then the instanced solver opening only the instances in view (`render --open-in-view`)
against opening them all, on the plantation seen from its edge and on a close-up of the
119k tree's crown, from the phase functions the first pictures stored: instances opened,
solve time and peak memory, and how far the two pictures are apart on the linear grey
scale (render_culling.csv).

Usage: bench_render.py BUILD_DIR OUT_DIR [--size 1024x768] [--pixel-samples 4]
Writes OUT_DIR/render.csv (picture, scene, solver, size, rays, render_s, scale_max, png)
and the pictures OUT_DIR/render_*.png, and prints the table.
"""
import argparse
import csv
import math
import os
import re
import subprocess

# name: (how to make the scene, the camera)
SCENES = {
    "tree119k": (["--leaves", "44500", "--seed", "2", "--sky-cones", "turtle46"],
                 "eye=20,-22,9 look=0,0,7.5 fov=45"),
    "plantation": (["--leaves", "2000", "--seed", "2", "--rows", "4", "--columns", "4", "--spacing", "4"],
                   "eye=14,-18,9 look=0,0,2 fov=45"),
    "plantation_rgb": (["--leaves", "2000", "--seed", "2", "--rows", "4", "--columns", "4", "--spacing", "4",
                        "--colour-bands"], "eye=14,-18,9 look=0,0,2 fov=45"),
    "greenhouse": (["--greenhouse", "--rows", "3", "--columns", "8", "--spacing", "0.8", "--row-spacing", "1.4",
                    "--leaves", "200", "--leaf-length", "0.06"],
                   "eye=-0.7,-2.9,1.5 look=0.2,2,0.2 fov=70"),
}
# The pictures: (name, scene, solver, what to draw); pictures of one scene share one colour
# scale.
PICTURES = [("tree119k_hrc", "tree119k", "hrc", []), ("tree119k_instanced", "tree119k", "instanced", []),
            ("plantation_hrc", "plantation", "hrc", []), ("greenhouse_hrc", "greenhouse", "hrc", []),
            ("plantation_colour", "plantation_rgb", "hrc", ["--quantity", "colour", "--scale-bar", "--north-arrow"])]


def render(leaflux, scene, leaves, camera, png, size, samples, what, scale_max=None):
    """Draws `leaves` (a solve's CSV) on `scene`; returns (rays, seconds, the scale's top)."""
    command = [leaflux, "render", "--scene", scene, "--from", leaves, "--camera", camera, "--size", size,
               "--pixel-samples", str(samples), "--out", png, *what]
    if scale_max is not None:
        command += ["--range", f"0,{scale_max}"]
    text = subprocess.run(command, check=True, capture_output=True, text=True).stdout
    match = re.search(r"from \S+ to (\S+), (\d+) rays in (\S+) s", text)
    return int(match.group(2)), float(match.group(3)), float(match.group(1))


# Views that see part of a scene: (name, scene, camera).
CULLING = [("plantation_edge", "plantation", "eye=-6,-12,2.5 look=-6,-6,2.5 fov=30"),
           ("tree119k_crown", "tree119k", "eye=3,-4,8 look=2,0,8 fov=35")]


def culling_rows(leaflux, out, size, samples):
    """Each CULLING view solved by the instanced solver twice, opening every instance and
    those in view alone; the two pictures on one grey scale, compared pixel by pixel."""
    import matplotlib.image
    rows = []
    for name, scene_name, camera in CULLING:
        scene = os.path.join(out, f"{scene_name}.scene.txtpb")
        runs = {}
        for how, flag in (("all", []), ("in_view", ["--open-in-view"])):
            png = os.path.join(out, f"culling_{name}_{how}.png")
            text = subprocess.run([leaflux, "render", "--scene", scene, "--solver", "instanced", "--phase-db",
                                   os.path.join(out, "phase.db"), "--camera", camera, "--size", size,
                                   "--pixel-samples", str(samples), "--palette", "grey", "--range", "0,500",
                                   "--out", png, *flag], check=True, capture_output=True, text=True).stdout
            depths = re.search(r"instances by depth \(opened\):(.*?)(;|\n)", text).group(1)
            pairs = re.findall(r"\d+: (\d+) \((\d+)\)", depths)
            solving = float(re.search(r"solving (\S+) s", text).group(1))
            peak = float(re.search(r"peak (\S+) MiB", text).group(1))
            runs[how] = (sum(int(a) for a, _ in pairs), sum(int(b) for _, b in pairs), solving, peak, png)
        a = matplotlib.image.imread(runs["all"][4])[..., 0]
        b = matplotlib.image.imread(runs["in_view"][4])[..., 0]
        height = int(size.split("x")[1])  # the view, not the colour bar below it
        delta = abs(a[:height] - b[:height])  # grey levels / 255: W/m² / 500
        rows.append({"view": name, "instances": runs["all"][0], "opened_all": runs["all"][1],
                     "opened_in_view": runs["in_view"][1], "solve_s_all": runs["all"][2],
                     "solve_s_in_view": runs["in_view"][2], "peak_mib_all": runs["all"][3],
                     "peak_mib_in_view": runs["in_view"][3], "mean_abs_wm2": 500.0 * float(delta.mean()),
                     "pixels_apart_pct": 100.0 * float((delta > 1.5 / 255).mean())})
    return rows


def round_up(value):
    """`value` rounded up to three significant digits: a scale's top above every value."""
    step = 10.0 ** (math.floor(math.log10(value)) - 2)
    return f"{math.ceil(value / step) * step:.6g}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("build", help="the build folder, with server/leaflux")
    parser.add_argument("out", help="folder of the scenes, render.csv and the pictures (made when missing)")
    parser.add_argument("--size", default="1024x768", help="the view's size in pixels (default: %(default)s)")
    parser.add_argument("--pixel-samples", type=int, default=4, help="rays a pixel (default: %(default)s)")
    args = parser.parse_args()
    leaflux = os.path.join(args.build, "server", "leaflux")
    os.makedirs(args.out, exist_ok=True)
    solved = {}
    for name, scene_name, solver, _ in PICTURES:
        scene = os.path.join(args.out, f"{scene_name}.scene.txtpb")
        if not os.path.exists(scene):
            subprocess.run([leaflux, "generate", *SCENES[scene_name][0], "--out", scene], check=True,
                           capture_output=True)
        leaves = os.path.join(args.out, f"{name}.csv")
        subprocess.run([leaflux, "solve", "--scene", scene, "--solver", solver, "--quiet", "--out", leaves,
                        "--phase-db", os.path.join(args.out, "phase.db")] if solver == "instanced" else
                       [leaflux, "solve", "--scene", scene, "--solver", solver, "--quiet", "--out", leaves],
                       check=True, capture_output=True)
        solved[name] = (scene, leaves)
    # The scale of a scene's pictures: 0 to the largest value any of them has in view.
    tops = {}
    for name, scene_name, _, what in PICTURES:
        scene, leaves = solved[name]
        png = os.path.join(args.out, f"render_{name}.png")
        top = render(leaflux, scene, leaves, SCENES[scene_name][1], png, args.size, args.pixel_samples, what)[2]
        tops[scene_name] = max(tops.get(scene_name, 0.0), top)
    rows = []
    for name, scene_name, solver, what in PICTURES:
        scene, leaves = solved[name]
        png = os.path.join(args.out, f"render_{name}.png")
        rays, seconds, top = render(leaflux, scene, leaves, SCENES[scene_name][1], png, args.size,
                                    args.pixel_samples, what, round_up(tops[scene_name]))
        rows.append({"picture": name, "scene": scene_name, "solver": solver, "size": args.size,
                     "pixel_samples": args.pixel_samples, "rays": rays, "render_s": seconds,
                     "scale_max": top, "png": os.path.basename(png)})
    with open(os.path.join(args.out, "render.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    print(f"{'picture':<22}{'size':>10}{'rays':>12}{'render s':>10}{'scale max':>11}")
    for r in rows:
        print(f"{r['picture']:<22}{r['size']:>10}{r['rays']:>12,}{r['render_s']:>10.3f}{r['scale_max']:>11.4g}")
    culling = culling_rows(leaflux, args.out, args.size, args.pixel_samples)
    with open(os.path.join(args.out, "render_culling.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(culling[0]))
        writer.writeheader()
        writer.writerows(culling)
    for r in culling:
        print(f"{r['view']}: {r['opened_in_view']} of {r['instances']} instances opened in view "
              f"(all: {r['opened_all']}); solve {r['solve_s_in_view']:.2f} s against {r['solve_s_all']:.2f} s, "
              f"peak {r['peak_mib_in_view']:.0f} against {r['peak_mib_all']:.0f} MiB; pictures apart by "
              f"{r['mean_abs_wm2']:.3g} W/m² on average, {r['pixels_apart_pct']:.2g} % of pixels by more than a grey level")


if __name__ == "__main__":
    main()
