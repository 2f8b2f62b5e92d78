#!/usr/bin/python3
"""Draws every benchmarked mesh with its skeleton over it: out/bench/contact_sheet.png.

    PYTHONPATH=build/python /usr/bin/python3 scripts/contact_sheet.py \\
        --out out/bench/contact_sheet.png out/bench/skeletons [FILE.json ...]

The inputs are the skeleton files of `dcg_bench --skeleton-dir` (scripts/bench.py writes them
to out/bench/skeletons/): each names its mesh file, read with dcg.load_mesh. One tile per mesh:
the mesh shaded and faded (a numpy z-buffer, orthographic, with its silhouette outlined), the
skeleton in front of it: links as lines, nodes colored by kind like the paper and the add-on
(end red, joint purple, connection blue), the mesh's name and counts under the tile.

The view: world Y is up, looking along whichever of the other two axes the mesh is thinnest
in (the largest silhouette), turned 30 degrees about the up axis and raised 15 degrees so that
left and right limbs do not hide each other (VIEWS overrides the up axis and the turn for a few
public meshes). --skeleton mcf draws CGAL's mean curvature flow skeleton instead (its edges,
orange), to compare. numpy and matplotlib (both installed by scripts/install-deps.sh) only.
"""
import argparse
import json
import sys
from pathlib import Path

import numpy as np

# Views of the public meshes where the rule below hides a part: (up axis, yaw in degrees).
VIEWS = {"horse.ply": (2, 30),     # stored Z up
         "dino.off": (2, 30),      # from above: the four legs spread apart
         "kitten.off": (1, -60)}   # from the side: the tail's loop
# Node colors: the add-on's (addon/dcg_rig/armature.py KIND_COLORS), the paper's scheme.
KIND_COLORS = {"end": (0.90, 0.12, 0.10), "joint": (0.60, 0.15, 0.85),
               "connection": (0.10, 0.35, 0.95)}
KIND_SIZES = {"end": 34, "joint": 40, "connection": 9}
MESH_COLOR = np.array([0.62, 0.66, 0.72])
OUTLINE = np.array([0.35, 0.37, 0.40])
MESH_OPACITY = 0.55


def view_rotation(V, name, pitch_deg=15.0):
    """3 by 3 rotation whose rows are the screen's right, up and towards-the-viewer axes."""
    up_axis, yaw_deg = VIEWS.get(name, (1, 30.0))
    extent = V.max(axis=0) - V.min(axis=0)
    others = [a for a in range(3) if a != up_axis]
    depth_axis = min(others, key=lambda a: extent[a])
    up = np.eye(3)[up_axis]
    toward = np.eye(3)[depth_axis]
    right = np.cross(up, toward)
    # Turn about up by yaw, then tilt the view down by pitch (the camera a little above).
    yaw, pitch = np.radians(yaw_deg), np.radians(pitch_deg)
    toward, right = (np.cos(yaw) * toward + np.sin(yaw) * right,
                     np.cos(yaw) * right - np.sin(yaw) * toward)
    toward, up = (np.cos(pitch) * toward + np.sin(pitch) * up,
                  np.cos(pitch) * up - np.sin(pitch) * toward)
    return np.stack([right, up, toward])


def rasterize(P, F, width, height):
    """Z-buffer of triangles F (#F by 3) over screen points P (#V by 3: x, y pixels, depth
    towards the viewer). Returns #H by #W face indices (-1: background)."""
    fid = np.full(height * width, -1, dtype=np.int64)
    zbuf = np.full(height * width, -np.inf)
    T = P[F]  # #F by 3 by 3
    lo = np.floor(T[:, :, :2].min(axis=1)).astype(np.int64)
    hi = np.ceil(T[:, :, :2].max(axis=1)).astype(np.int64)
    lo = np.maximum(lo, 0)
    hi = np.minimum(hi, [width - 1, height - 1])
    size = hi - lo + 1
    keep = (size > 0).all(axis=1)
    faces = np.nonzero(keep)[0]
    span = size[faces].max(axis=1)
    # Buckets of faces by the side of their pixel box, so that each bucket is one array op.
    edges = [0, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1 << 30]
    for b0, b1 in zip(edges[:-1], edges[1:]):
        in_bucket = faces[(span > b0) & (span <= b1)]
        if in_bucket.size == 0:
            continue
        side = min(b1, max(width, height))
        ox, oy = np.meshgrid(np.arange(side), np.arange(side))
        ox, oy = ox.ravel(), oy.ravel()
        chunk = max(1, 4_000_000 // (side * side))
        for c in range(0, in_bucket.size, chunk):
            f = in_bucket[c:c + chunk]
            x = lo[f, 0][:, None] + ox[None, :]
            y = lo[f, 1][:, None] + oy[None, :]
            valid = (x <= hi[f, 0][:, None]) & (y <= hi[f, 1][:, None])
            px, py = x + 0.5, y + 0.5
            a, b, c3 = T[f, 0], T[f, 1], T[f, 2]
            area = ((b[:, 0] - a[:, 0]) * (c3[:, 1] - a[:, 1])
                    - (b[:, 1] - a[:, 1]) * (c3[:, 0] - a[:, 0]))
            area = np.where(np.abs(area) < 1e-12, np.nan, area)[:, None]
            w0 = ((b[:, 0, None] - px) * (c3[:, 1, None] - py)
                  - (b[:, 1, None] - py) * (c3[:, 0, None] - px)) / area
            w1 = ((c3[:, 0, None] - px) * (a[:, 1, None] - py)
                  - (c3[:, 1, None] - py) * (a[:, 0, None] - px)) / area
            w2 = 1 - w0 - w1
            inside = valid & (w0 >= 0) & (w1 >= 0) & (w2 >= 0)
            rows, cols = np.nonzero(inside)
            if rows.size == 0:
                continue
            z = (w0[rows, cols] * a[rows, 2] + w1[rows, cols] * b[rows, 2]
                 + w2[rows, cols] * c3[rows, 2])
            pix = y[rows, cols] * width + x[rows, cols]
            order = np.lexsort((-z, pix))  # by pixel, nearest first
            pix, z, face = pix[order], z[order], f[rows[order]]
            first = np.ones(pix.size, dtype=bool)
            first[1:] = pix[1:] != pix[:-1]
            pix, z, face = pix[first], z[first], face[first]
            nearer = z > zbuf[pix]
            zbuf[pix[nearer]] = z[nearer]
            fid[pix[nearer]] = face[nearer]
    return fid.reshape(height, width)


def mesh_picture(V, F, R, scale, offset, size, supersample=2):
    """#size by #size by 4 RGBA picture of the mesh (shaded, faded, outlined)."""
    n = size * supersample
    P = V @ R.T
    P[:, :2] = (P[:, :2] * scale + offset) * supersample
    P[:, 1] = n - P[:, 1]  # image rows go down
    fid = rasterize(P, F, n, n)
    Q = V @ R.T
    normals = np.cross(Q[F[:, 1]] - Q[F[:, 0]], Q[F[:, 2]] - Q[F[:, 0]])
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
    light = np.array([-0.3, 0.5, 1.0])
    light /= np.linalg.norm(light)
    shade = 0.45 + 0.55 * np.abs(normals @ light)  # two-sided: windings vary
    covered = fid >= 0
    rgb = np.ones((n, n, 3))
    rgb[covered] = MESH_COLOR * shade[fid[covered]][:, None]
    alpha = np.where(covered, MESH_OPACITY, 0.0)
    # The silhouette: covered pixels next to background.
    edge = np.zeros_like(covered)
    edge[1:, :] |= covered[1:, :] != covered[:-1, :]
    edge[:-1, :] |= covered[1:, :] != covered[:-1, :]
    edge[:, 1:] |= covered[:, 1:] != covered[:, :-1]
    edge[:, :-1] |= covered[:, 1:] != covered[:, :-1]
    edge &= covered
    rgb[edge] = OUTLINE
    alpha[edge] = 0.9
    rgba = np.concatenate([rgb, alpha[..., None]], axis=2)
    return rgba.reshape(size, supersample, size, supersample, 4).mean(axis=(1, 3))


def draw_tile(ax, record, V, F, size, skeleton="ours"):
    name = record["mesh"]
    R = view_rotation(V, name)
    ours = (record.get("ours") or {}) if skeleton == "ours" else {}
    Q = V @ R.T
    lo, hi = Q[:, :2].min(axis=0), Q[:, :2].max(axis=0)
    scale = 0.9 * size / max(float((hi - lo).max()), 1e-30)
    offset = size / 2 - scale * (lo + hi) / 2
    ax.imshow(mesh_picture(V, F, R, scale, offset, size), extent=(0, size, 0, size),
              interpolation="bilinear")

    def screen(points):
        p = np.asarray(points, dtype=float).reshape(-1, 3) @ R.T
        return p[:, :2] * scale + offset

    for line in ours.get("polylines") or []:
        s = screen(line)
        ax.plot(s[:, 0], s[:, 1], color="#222222", lw=1.1, solid_capstyle="round", zorder=2)
    kinds = np.array(ours.get("kinds") or [], dtype=str)
    positions = screen(ours["positions"]) if len(kinds) else np.zeros((0, 2))
    for kind in ("connection", "joint", "end"):
        chosen = kinds == kind
        if chosen.any():
            ax.scatter(positions[chosen, 0], positions[chosen, 1], s=KIND_SIZES[kind],
                       c=[KIND_COLORS[kind]], edgecolors="white", linewidths=0.5, zorder=3)
    mcf = (record.get("mcf") or {}) if skeleton == "mcf" else {}
    if mcf:
        points = screen(mcf["points"])
        for a, b in mcf["edges"]:
            ax.plot(points[[a, b], 0], points[[a, b], 1], color="#e07000", lw=1.2, zorder=2)
    counts = {k: int((kinds == k).sum()) for k in KIND_COLORS}
    def plural(n, word):
        return f"{n} {word}" + ("" if n == 1 else "s")
    detail = (f"{plural(counts['end'], 'end')}, {plural(counts['joint'], 'joint')}, "
              f"{counts['connection']} conn." if ours else "no skeleton")
    if skeleton == "mcf":
        detail = (f"MCF: {len(mcf['points'])} vertices, {len(mcf['edges'])} edges" if mcf
                  else "MCF not run")
    ax.set_xlim(0, size)
    ax.set_ylim(0, size)
    ax.set_xticks([])
    ax.set_yticks([])
    for spine in ax.spines.values():
        spine.set_color("#cccccc")
    ax.set_xlabel(f"{name}\n{detail}", fontsize=9, labelpad=3)


def skeleton_files(paths):
    files = []
    for p in map(Path, paths):
        files += sorted(p.glob("*.json")) if p.is_dir() else [p]
    return files


def make_contact_sheet(files, out, columns=6, tile=300, dpi=100, skeleton="ours"):
    """Writes the contact sheet of the skeleton files `files` to `out` (skeleton: "ours" or
    "mcf"); returns the number of tiles drawn. Meshes that cannot be read are skipped with a
    message on stderr."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import dcg

    items = []
    for f in files:
        record = json.loads(Path(f).read_text())
        try:
            V, F = dcg.load_mesh(record["path"])
        except (OSError, ValueError) as e:
            print(f"contact_sheet: {record.get('mesh', f)}: {e}", file=sys.stderr)
            continue
        items.append((record, V, F))
    if not items:
        raise SystemExit("contact_sheet: nothing to draw")
    columns = min(columns, len(items))
    rows = (len(items) + columns - 1) // columns
    inch = tile / dpi
    fig, axes = plt.subplots(rows, columns, figsize=(columns * inch, rows * (inch + 0.45) + 0.4),
                             dpi=dpi, squeeze=False)
    for ax in axes.ravel()[len(items):]:
        ax.axis("off")
    for ax, (record, V, F) in zip(axes.ravel(), items):
        draw_tile(ax, record, V, F, tile, skeleton)
    if skeleton == "mcf":
        handles = [plt.Line2D([], [], color="#e07000", lw=1.2,
                              label="CGAL mean curvature flow skeleton (edges)")]
    else:
        handles = [plt.Line2D([], [], ls="", marker="o", ms=7, color=KIND_COLORS[k], label=k)
                   for k in ("end", "joint", "connection")]
        handles.append(plt.Line2D([], [], color="#222222", lw=1.1, label="link"))
    fig.legend(handles=handles, loc="upper center", ncol=4, frameon=False, fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 1 - 0.35 / (rows * (inch + 0.45) + 0.4)), h_pad=0.6)
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=dpi, facecolor="white")
    plt.close(fig)
    return len(items)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("inputs", nargs="+", help="skeleton .json files or folders of them")
    parser.add_argument("--out", default="out/bench/contact_sheet.png")
    parser.add_argument("--columns", type=int, default=6)
    parser.add_argument("--tile", type=int, default=300, help="tile side in pixels")
    parser.add_argument("--skeleton", choices=("ours", "mcf"), default="ours",
                        help="which skeleton to draw (default ours)")
    args = parser.parse_args()
    n = make_contact_sheet(skeleton_files(args.inputs), args.out, args.columns, args.tile,
                           skeleton=args.skeleton)
    print(f"contact_sheet: wrote {args.out} ({n} meshes)", file=sys.stderr)


if __name__ == "__main__":
    main()
