"""Runs `leaflux generate` and `leaflux solve` for the benchmark scripts, and reads the
solve's one-line summary."""
import os
import re
import subprocess


def solve(leaflux, scene, out, options):
    """Solves `scene` into `out` (CSV) and returns the summary's figures: wall_s, cpu_s,
    peak_mib (the process's, loading included), loaded_mib (its memory once the scene was
    loaded) and solving_mib (its peak from then on: less loaded_mib, the solver's working
    memory), links and elements ("" for Monte Carlo), the energy balance residual in % per
    band, and for the instanced solver phase_computed (the phase functions its database
    lacked)."""
    output = subprocess.run([leaflux, "solve", "--scene", scene, "--quiet", "--out", out] + options,
                            check=True, capture_output=True, text=True).stdout
    line = output.strip().splitlines()[-1]
    found = lambda pattern: re.search(pattern, line)
    row = dict(wall_s=float(found(r" in ([0-9.e+-]+) s").group(1)),
               cpu_s=float(found(r"cpu ([0-9.e+-]+) s").group(1)),
               peak_mib=int(found(r"peak ([0-9]+) MiB").group(1)))
    # Where the kernel let the peak be reset after loading ("" where it did not).
    loaded = found(r"\(([0-9]+) MiB with the scene loaded, ([0-9]+) MiB at most while solving\)")
    row["loaded_mib"], row["solving_mib"] = (int(loaded.group(1)), int(loaded.group(2))) if loaded else ("", "")
    computed = re.search(r"phase functions: ([0-9]+) computed", output)
    if computed:
        row["phase_computed"] = int(computed.group(1))
    links = found(r"([0-9]+) links, ([0-9]+) elements")
    row["links"], row["elements"] = (int(links.group(1)), int(links.group(2))) if links else ("", "")
    row["residual_pct"] = {band: float(r) for band, r in
                           re.findall(r"(\w+): incident [^;]*residual ([-0-9.e+]+) %", line)}
    return row


def generate_tree(leaflux, out_dir, leaves, sky_cones="continuous"):
    """Writes the benchmarks' generated tree of `leaves` leaves (seed 2); returns its path."""
    scene = os.path.join(out_dir, f"tree{leaves}.scene.txtpb")
    subprocess.run([leaflux, "generate", "--leaves", str(leaves), "--seed", "2", "--sky-cones", sky_cones,
                    "--out", scene], check=True, capture_output=True)
    return scene
