#!/usr/bin/env python3
"""Generate a sweep of connecting rods: a Latin-hypercube sample of make_designs.py's shape parameters.

    rodstudy sweep generate --count N --seed S --out DIR [--bounds FILE]
    python pipeline/sweep_designs.py --count N --seed S --out DIR [--bounds FILE]

Every rod is built exactly as the five committed designs are (pipeline/make_designs.py, imported,
not copied: `build_rod`, `surface_triangles`, `orient_outward`, `validate_mesh`, `pin_axes_clear`,
`stl_bytes`, `check_sensible`, ...), with the same mechanism interface: millimetres, crank-pin bore
50 mm at A = (0, 0, 0), piston-pin bore 25 mm at B = (180, 0, 0), pin axis z, density 7800 kg/m^3.
There is no calibration to thesis Table 5.1: a sweep rod's parameters are the sample.

Output in DIR (created if needed; refused if it holds other files than the ones this run writes):
  rodNNNN.stl   binary STL in mm (ids rod0001, rod0002, ... zero-padded to the width of N, at least 4)
  rodNNNN.toml  the sidecar, same keys as designs/design1.toml (name, units, density, crank_pin,
                piston_pin, pin_axis). The sampled parameters are recorded as comment lines
                `# key = value` (TOML syntax behind the `#`): the Rust sidecar reader refuses every
                unknown key or table (serde deny_unknown_fields), so they cannot be real keys.
  sweep.json    seed, count, sampler, bounds, fixed parameters, and per rod: id, files, kind,
                parameters, whether it is still on its Latin-hypercube strata, every replaced
                attempt with its parameters and reason, triangle count, mass, l1, I_xx of the STL.
                sweep.json is written last: a folder without it is an incomplete run.
The same seed, count and bounds give byte-identical files (no times, paths or dates are written;
gmsh runs single-threaded with fixed options, see make_designs.MESH_OPTIONS). Times are only printed.

Parameters and default bounds (mm)
----------------------------------
  kind            "ibeam", "solid" or "slot": the shank types of make_designs.build_rod (designs 1
                  and 3 are I-beams, 2 and 5 solid, 4 slotted)
  eye_a_r         36 .. 44   big-end eye outer radius (wall 11-19 mm around the 50 mm bore; designs 42)
  eye_b_r         24 .. 32   small-end eye outer radius (wall 11.5-19.5 mm around the 25 mm bore;
                             designs 25.5-30.6)
  eye_t           36 .. 44   eye thickness along z (thesis rods and designs: 40)
  boss_half_span  54 .. 64   bolt bosses reach |y| <= this (designs 52-58). At least 54: where the
                             boss side face x = +-15 is shorter than the junction fillet (8) plus the
                             corner rounding (4), OpenCASCADE's fillet fails (seen with eye_a_r 46,
                             boss_half_span 50.6)
  shank_t         24 .. 36   shank thickness along z (designs 26-40); at most eye_t's minimum, so the
                             shank is never thicker than the eyes
  shank_h         15 .. 24   shank half-width at mid-length (designs 7-26)
  shank_dh         0 .. 6    taper: half-width shank_h + shank_dh at A, shank_h - shank_dh at B
  flange           5 .. 9    I-beam flange width / slot rail width   (kinds ibeam, slot only; designs 7-12)
  web              6 .. 16   I-beam web thickness along z           (kind ibeam only; designs 12-21)
Everything else is make_designs.COMMON (boss_half_len 15, pocket_gap 3, fillet_r 8, boss_corner_r 4,
pocket_corner_r 4). About 2 % of the uniform draws in this box fail make_designs.check_sensible
(shank wider than the small-end eye; pocket or slot too narrow at the small end); none of 293
sensible draws failed in OpenCASCADE.

Sampling
--------
rng = numpy.random.Generator(numpy.random.PCG64(seed)). The sample has one dimension per parameter,
in the order above (`kind` first; then any extra parameters named in the bounds file, in
make_designs.COMMON order). For each dimension j in order, perm_j = rng.permutation(N); then
jitter = rng.random((N, D)); the unit coordinate of rod i is u[i, j] = (perm_j[i] + jitter[i, j]) / N
(one rod per stratum of width 1/N in every dimension). A parameter is min + u (max - min), rounded to
1e-4 mm (the built geometry is the recorded value); kind is kinds[floor(u * len(kinds))].
Parameters a kind does not use (flange for solid, web for solid and slot) are drawn but neither used
nor recorded.

Replacement
-----------
Rods are built in id order. A parameter set is replaced when it
  * fails make_designs.check_sensible (walls < 5 mm, shank wider or thicker than the eyes, pockets
    too narrow or shallow, ...),
  * cannot be built by OpenCASCADE as one solid (fuse, fillet or cut failure: gmsh error / assert),
  * cannot be meshed, or its surface mesh fails make_designs.validate_mesh (closed, 2-manifold,
    consistently oriented, one shell, no degenerate triangle, positive volume),
  * has material on a pin axis (make_designs.pin_axes_clear), or its tessellation moves the mass by
    more than make_designs.CHORD_MASS_REL_MAX against the exact B-rep,
  * gives a written STL that does not read back as a valid mesh.
The replacement is drawn from the same generator stream, right then (so deterministically): the
first 3 replacements re-jitter inside the rod's own strata, u[i, j] = (perm_j[i] + rng.random()) / N
for every j (the sample stays a Latin hypercube); later ones draw u uniformly in the whole box
(u = rng.random(D); the rod is then marked "stratified": false). After 100 attempts for one rod the
run stops with exit status 1 (the bounds are then unusable) and writes no sweep.json. Every replaced
attempt is printed, counted by reason in the final summary, and listed in sweep.json: nothing is
dropped silently.

Bounds file (--bounds FILE, TOML if FILE ends in .toml, else JSON)
------------------------------------------------------------------
A table of parameters, each overriding its default min and/or max; `kind` lists the shank types to
draw from. Parameters of make_designs.COMMON not sampled by default may be named too: they are then
sampled as well (appended to the dimensions). min == max fixes a parameter. Unknown names, min > max,
non-numbers and unknown kinds are errors (exit status 2). Example (TOML):

    kind = ["ibeam", "slot"]
    eye_t = { min = 38.0, max = 42.0 }
    shank_h = { max = 22.0 }
    fillet_r = { min = 5.0, max = 9.0 }      # sampled too

or as JSON: {"kind": ["ibeam", "slot"], "eye_t": {"min": 38, "max": 42}, "shank_h": {"max": 22}}

Exit status: 0 all rods written, 1 a rod could not be made within the attempt limit, 2 usage error.
"""

from __future__ import annotations

import argparse
import collections
import json
import math
import pathlib
import re
import sys
import time
import tomllib

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import make_designs as md  # noqa: E402  (the rod builder, validation and writers)

import gmsh  # noqa: E402

KINDS = ("ibeam", "solid", "slot")
KIND_LABEL = {"ibeam": "I-beam shank", "solid": "solid shank", "slot": "slotted shank"}
DEFAULT_BOUNDS = {  # mm; see the module docstring for the reasons
    "eye_a_r": (36.0, 44.0),
    "eye_b_r": (24.0, 32.0),
    "eye_t": (36.0, 44.0),
    "boss_half_span": (54.0, 64.0),
    "shank_t": (24.0, 36.0),
    "shank_h": (15.0, 24.0),
    "shank_dh": (0.0, 6.0),
    "flange": (5.0, 9.0),
    "web": (6.0, 16.0),
}
USED_BY = {"flange": ("ibeam", "slot"), "web": ("ibeam",)}  # parameters only some kinds use
STRATIFIED_RETRIES = 3  # replacements that re-jitter within the rod's strata
MAX_ATTEMPTS = 100  # per rod
DIGITS = 4  # parameters rounded to 1e-4 mm (make_designs.PARAM_ROUND_MM)


class UsageError(Exception):
    pass


class Rejected(Exception):
    """A parameter set that does not give a valid rod: `category` (for the summary) and details."""

    def __init__(self, category: str, detail: str):
        super().__init__(f"{category}: {detail}")
        self.category, self.detail = category, detail

    def key(self) -> str:
        """The reason without the numbers of this draw, for counting (first line only)."""
        return re.sub(r" \([^()]*\d[^()]*\)", "", str(self).splitlines()[0])


# ---------------------------------------------------------------------------------------------
# Bounds
# ---------------------------------------------------------------------------------------------

def load_bounds(path: pathlib.Path | None):
    """(kinds, {name: (min, max)} in dimension order) from the defaults and an optional file."""
    kinds = list(KINDS)
    bounds = dict(DEFAULT_BOUNDS)
    if path is None:
        return kinds, bounds
    try:
        text = path.read_bytes()
    except OSError as e:
        raise UsageError(f"{path}: cannot read the bounds file: {e}") from e
    try:
        data = tomllib.loads(text.decode()) if path.suffix.lower() == ".toml" else json.loads(text)
    except (ValueError, UnicodeDecodeError) as e:  # TOMLDecodeError and JSONDecodeError are ValueErrors
        raise UsageError(f"{path}: not valid {'TOML' if path.suffix.lower() == '.toml' else 'JSON'}: {e}") from e
    if not isinstance(data, dict):
        raise UsageError(f"{path}: expected a table of parameters")
    extra = []
    for name, value in data.items():
        if name == "kind":
            if (not isinstance(value, list) or not value or any(k not in KINDS for k in value)
                    or len(set(value)) != len(value)):
                raise UsageError(f"{path}: `kind` must be a non-empty list of distinct kinds from {list(KINDS)}, "
                                 f"got {value!r}")
            kinds = [k for k in KINDS if k in value]  # canonical order: the sample does not depend on spelling
            continue
        if name not in md.COMMON:
            raise UsageError(f"{path}: unknown parameter {name!r}; known: kind, {', '.join(md.COMMON)}")
        if not isinstance(value, dict) or not value or set(value) - {"min", "max"}:
            raise UsageError(f"{path}: `{name}` must be a table with `min` and/or `max`, got {value!r}")
        lo, hi = bounds.get(name, (md.COMMON[name], md.COMMON[name]))
        lo, hi = value.get("min", lo), value.get("max", hi)
        for v in (lo, hi):
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise UsageError(f"{path}: `{name}` bounds must be finite numbers, got {v!r}")
        if lo > hi:
            raise UsageError(f"{path}: `{name}`: min {lo} > max {hi}")
        if name not in bounds:
            extra.append(name)
        bounds[name] = (float(lo), float(hi))
    ordered = {k: bounds[k] for k in DEFAULT_BOUNDS}
    ordered.update((k, bounds[k]) for k in md.COMMON if k in extra)
    return kinds, ordered


# ---------------------------------------------------------------------------------------------
# Sampling
# ---------------------------------------------------------------------------------------------

class Sampler:
    """Latin hypercube over [kind] + parameters, with replacement draws from the same stream."""

    def __init__(self, seed: int, count: int, kinds, bounds: dict):
        self.rng = np.random.Generator(np.random.PCG64(seed))
        self.n, self.kinds, self.bounds = count, list(kinds), bounds
        self.dims = 1 + len(bounds)
        self.perm = np.stack([self.rng.permutation(count) for _ in range(self.dims)], axis=1)
        self.unit = (self.perm + self.rng.random((count, self.dims))) / count

    def rejitter(self, i: int) -> np.ndarray:
        return (self.perm[i] + self.rng.random(self.dims)) / self.n

    def uniform(self) -> np.ndarray:
        return self.rng.random(self.dims)

    def decode(self, u) -> tuple[str, dict]:
        kind = self.kinds[min(int(u[0] * len(self.kinds)), len(self.kinds) - 1)]
        params = {}
        for (name, (lo, hi)), uj in zip(self.bounds.items(), u[1:]):
            if kind in USED_BY.get(name, KINDS):
                params[name] = round(lo + float(uj) * (hi - lo), DIGITS) + 0.0  # + 0.0: no -0.0
        return kind, params


# ---------------------------------------------------------------------------------------------
# One rod
# ---------------------------------------------------------------------------------------------

def design_for(number: int, rod_id: str, kind: str, params: dict) -> md.Design:
    return md.Design(number, f"Sweep {rod_id}: {KIND_LABEL[kind]}", kind, {}, tuple(params),
                     tuple(params.values()))


def build(d: md.Design):
    """make_designs.tessellate step by step (to name the failing step): vertices, triangles, OCC props."""
    p = d.params()
    try:
        md.check_sensible(d, p)
    except AssertionError as e:
        raise Rejected("implausible parameters (check_sensible)", str(e).rsplit(": ", 1)[-1]) from e
    try:
        exact = md.occ_properties(md.build_rod(d, p))
    except Exception as e:  # gmsh raises Exception on an OCC error; build_rod asserts one solid
        raise Rejected("OpenCASCADE build failed", str(e) or type(e).__name__) from e
    try:
        verts, tris = md.surface_triangles()
    except Exception as e:
        raise Rejected("surface meshing failed", str(e) or type(e).__name__) from e
    try:
        tris = md.orient_outward(tris, verts)
        md.validate_mesh(verts, tris, d.name)
    except ValueError as e:
        raise Rejected("invalid surface mesh (validate_mesh)", str(e)) from e
    hits = md.pin_axes_clear(verts, tris, [(0.0, 0.0), (md.CENTRE_DISTANCE, 0.0)])
    if hits:
        raise Rejected("material on a pin axis", f"through {hits}")
    chord = md.mesh_mass_properties(verts, tris)["mass"] / exact["mass"] - 1.0
    if abs(chord) > md.CHORD_MASS_REL_MAX:
        raise Rejected("tessellation error", f"mesh mass differs from the exact B-rep by {chord:+.2e}")
    return verts, tris


def sidecar_text(d: md.Design, rod_id: str, seed: int, count: int, kind: str, params: dict) -> str:
    """make_designs' sidecar (the keys the Rust reader knows) behind comment lines with the sample."""
    body = md.sidecar_text(d).split("\n", 1)[1]  # drop make_designs' "generated by" comment
    lines = [f"# generated by pipeline/sweep_designs.py (rodstudy sweep generate --seed {seed} --count {count});"
             " do not edit, rerun",
             "# sampled parameters [mm] (comments: the sidecar reader accepts no other keys), see sweep.json:",
             f'# kind = "{kind}"']
    lines += [f"# {k} = {v:.{DIGITS}f}" for k, v in params.items()]
    return "\n".join(lines) + "\n" + body


def write_rod(out: pathlib.Path, d: md.Design, rod_id: str, verts, tris, sidecar: str, seed: int) -> dict:
    stl = out / f"{rod_id}.stl"
    header = f"rodstudy sweep {rod_id} seed {seed} binary STL, mm, gmsh {gmsh.__version__} OCC"
    stl.write_bytes(md.stl_bytes(verts, tris, header))
    # What the Rust pipeline will see: read the file back and check it again.
    v2, t2 = md.read_stl(stl)
    try:
        md.validate_mesh(v2, t2, str(stl))
    except ValueError as e:
        stl.unlink()
        raise Rejected("written STL invalid", str(e)) from e
    (out / f"{rod_id}.toml").write_text(sidecar)
    props = md.mesh_mass_properties(v2, t2)
    return {"triangles": int(len(t2)), "mass_kg": float(props["mass"]), "l1_mm": float(props["l1"]),
            "ixx_kgm2": float(props["ixx"])}


# ---------------------------------------------------------------------------------------------
# Driver
# ---------------------------------------------------------------------------------------------

def run(count: int, seed: int, out: pathlib.Path, kinds, bounds: dict) -> int:
    width = max(4, len(str(count)))
    ids = [f"rod{i:0{width}d}" for i in range(1, count + 1)]
    ours = {f"{r}.{ext}" for r in ids for ext in ("stl", "toml")} | {"sweep.json"}
    if out.exists() and not out.is_dir():
        raise UsageError(f"{out}: exists and is not a folder")
    if out.is_dir():
        others = sorted(p.name for p in out.iterdir() if p.name not in ours)
        if others:
            shown = ", ".join(others[:5]) + (", ..." if len(others) > 5 else "")
            raise UsageError(f"{out}: holds other files ({shown}); choose an empty or new folder")
    out.mkdir(parents=True, exist_ok=True)
    (out / "sweep.json").unlink(missing_ok=True)  # written last: its presence means a complete run

    sampler = Sampler(seed, count, kinds, bounds)
    md.gmsh_start()
    t_start = time.perf_counter()
    rods, reasons = [], collections.Counter()
    print(f"sweep: {count} rod(s), seed {seed}, Latin hypercube over kind {'/'.join(kinds)} and "
          f"{', '.join(bounds)}; gmsh {gmsh.__version__}", flush=True)
    for i, rod_id in enumerate(ids):
        t0 = time.perf_counter()
        u, stratified, replaced, why = sampler.unit[i], True, [], collections.Counter()
        while True:
            kind, params = sampler.decode(u)
            d = design_for(i + 1, rod_id, kind, params)
            try:
                verts, tris = build(d)
                record = write_rod(out, d, rod_id, verts, tris,
                                   sidecar_text(d, rod_id, seed, count, kind, params), seed)
                break
            except Rejected as e:
                replaced.append({"kind": kind, "parameters": params, "stratified": stratified,
                                 "reason": str(e)})
                reasons[e.key()] += 1
                why[e.key()] += 1
                print(f"  {rod_id}: replacing {kind} {md.fmt_params(d, d.params())}: {e}", flush=True)
            if len(replaced) >= MAX_ATTEMPTS:
                print(f"ERROR: {rod_id}: no valid rod in {MAX_ATTEMPTS} attempts; the bounds are unusable "
                      f"(reasons so far: {dict(reasons)})", flush=True)
                return 1
            if len(replaced) <= STRATIFIED_RETRIES:
                u = sampler.rejitter(i)
            else:
                u, stratified = sampler.uniform(), False
        rods.append({"id": rod_id, "stl": f"{rod_id}.stl", "sidecar": f"{rod_id}.toml", "kind": kind,
                     "parameters": params, "stratified": stratified, "attempts": len(replaced) + 1,
                     "replaced": replaced, **record})
        note = (f"; {len(replaced)} replaced (" + ", ".join(f"{n} x {w}" for w, n in why.items()) + ")"
                if replaced else "")
        print(f"{rod_id} {kind:5} mass {record['mass_kg']:.4f} kg, l1 {record['l1_mm']:.2f} mm, "
              f"I_xx {record['ixx_kgm2']:.3e} kg m^2, {record['triangles']} triangles, "
              f"{time.perf_counter() - t0:.1f} s{note}", flush=True)

    summary = {
        "generator": "pipeline/sweep_designs.py (rodstudy sweep generate)",
        "sampler": "Latin hypercube, numpy.random.Generator(numpy.random.PCG64(seed)); replacements drawn "
                   "from the same stream (see the script's docstring)",
        "seed": seed,
        "count": count,
        "kinds": kinds,
        "bounds": {k: {"min": lo, "max": hi} for k, (lo, hi) in bounds.items()},
        "parameters_used_only_by": {k: list(v) for k, v in USED_BY.items()},
        "fixed": {k: v for k, v in md.COMMON.items() if k not in bounds and k not in ("flange", "web")},
        "mechanism": {"units": "mm", "density_kg_m3": md.DENSITY, "crank_pin": [0.0, 0.0, 0.0],
                      "piston_pin": [md.CENTRE_DISTANCE, 0.0, 0.0], "pin_axis": "z",
                      "crank_bore_diameter": 2 * md.BORE_A_R, "piston_bore_diameter": 2 * md.BORE_B_R},
        "gmsh": gmsh.__version__,
        "replaced": sum(reasons.values()),
        "replaced_by_reason": dict(sorted(reasons.items())),
        "rods": rods,
    }
    (out / "sweep.json").write_text(json.dumps(summary, indent=2) + "\n")
    elapsed = time.perf_counter() - t_start
    print(f"\nwrote {count} rod(s) and sweep.json to {out} in {elapsed:.1f} s ({elapsed / count:.1f} s per rod)")
    n_rep = sum(reasons.values())
    if n_rep:
        print(f"{n_rep} parameter set(s) replaced: "
              + "; ".join(f"{n} x {why}" for why, n in sorted(reasons.items(), key=lambda kv: (-kv[1], kv[0]))))
    else:
        print("0 parameter sets replaced")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--count", type=int, required=True, help="number of rods (>= 1)")
    ap.add_argument("--seed", type=int, required=True, help="seed of numpy's PCG64 generator (>= 0)")
    ap.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    ap.add_argument("--bounds", type=pathlib.Path, help="TOML (.toml) or JSON file overriding min/max per parameter")
    args = ap.parse_args(argv)
    try:
        if args.count < 1:
            raise UsageError(f"--count must be at least 1, got {args.count}")
        if args.seed < 0:
            raise UsageError(f"--seed must be non-negative, got {args.seed}")
        kinds, bounds = load_bounds(args.bounds)
        return run(args.count, args.seed, args.out, kinds, bounds)
    except UsageError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    finally:
        if gmsh.isInitialized():
            gmsh.finalize()


if __name__ == "__main__":
    sys.exit(main())
