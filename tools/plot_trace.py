#!/usr/bin/python3
"""Plot a graspsim HDF5 trace over time.

    tools/plot_trace.py TRACE.h5 [--out FIG.png] [--compare B.h5]
                        [--objects a,b] [--fingers a,b] [--t0 S] [--t1 S]

Panels, on one shared time axis: object height and rotation from the first recorded pose;
per finger the normal force f_n, the tangential force |f_t| against the friction limit mu f_n,
the distance |GO - HIP| between god-object and haptic interface point, and stick/slip as a
coloured band; below, the paths of the god-objects and HIPs. --compare overlays a second trace
of the same scenario (dashed), aligned by simulated time.

How the quantities are derived from the trace (schema: recordings/README.md):
- contact normal n = (surface_point - HIP) / |surface_point - HIP| at each haptic tick, HIP
  taken from /servo at the same tick: the surface point is the HIP projected onto the
  contacted face (or the grown surface of a finger pad), so the difference is depth times the
  outward normal (|SP - HIP| equals `depth` to 1e-17 m in the shipped scenarios);
- f_n = F . n and f_t = F - f_n n, F the haptic `force` (the demanded contact force);
- the friction limit is mu f_n with mu = friction_radius / depth, which is the coefficient the
  engine used at that tick (static while sticking, kinetic while sliding). With viscous
  friction (c > 0) the engine's limit is mu_k f_n + c v and this gives mu_k f_n + c v f_n/(k depth),
  equal only while f_n = k depth; the trace does not record k or c v separately.

Exit status: 0 written, 2 bad input (missing file, not a graspsim trace, missing dataset,
unknown name, unwritable output), 1 when python3-h5py or python3-matplotlib is missing.
Needs Debian's python3-h5py and python3-matplotlib, hence /usr/bin/python3.
"""

import argparse
import os
import sys
import tempfile

SUPPORTED_SCHEMA = (1, 2, 3, 4)
STATE_NAMES = {0: "free", 1: "stick", 2: "slip"}
STATE_COLOURS = {0: "#e4e4e4", 1: "#4daf4a", 2: "#e41a1c"}


class BadInput(Exception):
    """Unusable input: message for the user, exit status 2."""


def text(value):
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    return str(value)


class Trace:
    """The parts of a trace the plot needs, as numpy arrays."""

    def __init__(self, path, np, h5py):
        self.path = path
        self.h5py = h5py
        self.tables = {}   # table dataset name -> {column: array} (table_columns)
        self.label = os.path.basename(path)
        if not os.path.exists(path):
            raise BadInput(f"{path}: no such file")
        if not os.path.isfile(path):
            raise BadInput(f"{path}: not a file")
        try:
            is_hdf5 = h5py.is_hdf5(path)
        except OSError as e:
            raise BadInput(f"{path}: cannot read ({e})")
        if not is_hdf5:
            raise BadInput(f"{path}: not an HDF5 file (not a graspsim trace)")
        try:
            f = h5py.File(path, "r")
        except OSError:
            # A file still open by a SWMR writer, or cut by a crash while it was, opens only in
            # SWMR read mode.
            try:
                f = h5py.File(path, "r", swmr=True)
            except OSError as e:
                raise BadInput(f"{path}: cannot open the HDF5 file ({e}); a trace cut by a crash "
                               "may need `graspsim repair` first")
        with f:
            self._read(f, np)

    def table_columns(self, table):
        """{column: array} of a table dataset, its rows read once. A member is a column (schema 3:
        "objects/b/position"); a member that is an array of compound elements (schema 4) is a
        group of entities named by the table's attribute of the member's name, one a line: field
        f of entity e is column "<member>/<e>/<f>"."""
        if table.name not in self.tables:
            rows = table[()]
            columns = {}
            for member in rows.dtype.names:
                sub = rows.dtype[member].subdtype
                if sub is None or sub[0].names is None:
                    columns[member] = rows[member]
                    continue
                entities = [e for e in text(table.attrs.get(member, "")).split("\n") if e]
                if len(entities) != sub[1][0]:
                    raise BadInput(f"{self.path}: {table.name}: member {member} holds {sub[1][0]} "
                                   f"entities but its attribute names {len(entities)}")
                for k, entity in enumerate(entities):
                    for field in sub[0].names:
                        columns[f"{member}/{entity}/{field}"] = rows[member][:, k][field]
            self.tables[table.name] = columns
        return self.tables[table.name]

    def split(self, f, name):
        """(columns of its table, column) for a column of a schema 3 or 4 table
        ("/physics/objects/b/position" is column "objects/b/position" of compound dataset
        "/physics"), else (None, None)."""
        table, _, member = name.lstrip("/").partition("/")
        obj = f.get(table)
        if isinstance(obj, self.h5py.Dataset) and obj.dtype.names is not None:
            return self.table_columns(obj), member
        return None, None

    def has(self, f, name):
        columns, member = self.split(f, name)
        if columns is not None:
            return member in columns
        return name in f

    def names_below(self, f, name):
        """Next path components below `name`: column-name prefixes (schema 3, 4) or group keys."""
        columns, member = self.split(f, name)
        if columns is not None:
            prefix = member + "/"
            return sorted({m[len(prefix):].split("/")[0] for m in columns if m.startswith(prefix)})
        return sorted(f[name].keys()) if name in f else []

    def need(self, f, name):
        if not self.has(f, name):
            raise BadInput(f"{self.path}: not a complete graspsim trace: missing dataset {name}")
        try:
            columns, member = self.split(f, name)
            return columns[member] if columns is not None else f[name][()]
        except (OSError, TypeError, ValueError) as e:
            raise BadInput(f"{self.path}: cannot read dataset {name} ({e})")

    def _read(self, f, np):
        if "schema_version" not in f.attrs:
            raise BadInput(f"{self.path}: not a graspsim trace (no root attribute schema_version)")
        try:
            version = int(f.attrs["schema_version"])
        except (TypeError, ValueError):
            raise BadInput(f"{self.path}: root attribute schema_version is not an integer")
        if version not in SUPPORTED_SCHEMA:
            raise BadInput(f"{self.path}: schema_version {version}; this script reads "
                           f"{', '.join(map(str, SUPPORTED_SCHEMA))}")
        self.status = text(f.attrs.get("status", "unknown"))
        self.scenario = text(f.attrs.get("scenario_name", "?"))
        self.parameters = text(f.attrs.get("parameters", "")).splitlines()
        self.rates = tuple(int(f.attrs[k]) if k in f.attrs else 0
                           for k in ("rate_servo", "rate_haptic", "rate_physics"))

        # Objects, in Model::bodies order (the /haptic attribute `bodies`), at physics ticks.
        self.t_physics = self.need(f, "/physics/time").astype(float)
        present = self.names_below(f, "/physics/objects")
        order = text(f["/haptic"].attrs.get("bodies", "")).split("\n") if "/haptic" in f else []
        self.body_names = [n for n in order if n]
        self.objects = [n for n in self.body_names if n in present] + \
            sorted(n for n in present if n not in self.body_names)
        self.object_data = {}
        for name in self.objects:
            g = f"/physics/objects/{name}/"
            pos = self.need(f, g + "position")
            quat = self.need(f, g + "quaternion")
            self.object_data[name] = {"position": pos, "quaternion": quat,
                                      "angle": rotation_from_start(quat, np)}

        # Fingers at haptic ticks; the HIP is taken from /servo at the same tick.
        self.t_haptic = self.need(f, "/haptic/time").astype(float)
        haptic_tick = self.need(f, "/haptic/tick")
        servo_tick = self.need(f, "/servo/tick")
        self.fingers = self._finger_order(f)
        self.finger_data = {}
        # Rows of /servo at the haptic ticks (a trace cut by a crash may lack some: NaN there).
        idx = np.searchsorted(servo_tick, haptic_tick)
        found = idx < len(servo_tick)
        found[found] = servo_tick[idx[found]] == haptic_tick[found]
        idx = np.where(found, idx, 0)
        for name in self.fingers:
            h = f"/haptic/fingers/{name}/"
            d = {k: self.need(f, h + k) for k in
                 ("god_object", "surface_point", "depth", "friction_radius", "force", "state",
                  "body", "slip")}
            hip_servo = self.need(f, f"/servo/fingers/{name}/hip")
            hip = np.full((len(haptic_tick), 3), np.nan)
            ok = found & (idx < len(hip_servo))
            hip[ok] = hip_servo[idx[ok]]
            d["hip"] = hip
            d.update(contact_forces(d, np))
            self.finger_data[name] = d

    def _finger_order(self, f):
        present = self.names_below(f, "/haptic/fingers")
        # Model::fingers order, when the runner's `devices` attribute ("name: kind" lines) has it.
        listed = [line.split(":")[0].strip() for line in text(f.attrs.get("devices", "")).splitlines()]
        ordered = [n for n in listed if n in present]
        return ordered + [n for n in present if n not in ordered]

    def param_lines(self):
        return [p for p in self.parameters if p.strip() and not p.startswith("scenario_source")]


def rotation_from_start(quat, np):
    """Angle (deg) of the rotation from the first recorded pose: q(t) q(0)^-1 (w, x, y, z)."""
    if len(quat) == 0:
        return np.zeros(0)
    q0 = quat[0]
    w0, v0 = q0[0], -q0[1:]   # conjugate of the first pose
    w, v = quat[:, 0], quat[:, 1:]
    rw = w * w0 - v @ v0
    rv = w[:, None] * v0 + w0 * v + np.cross(v, v0)
    return np.degrees(2.0 * np.arctan2(np.linalg.norm(rv, axis=1), np.abs(rw)))


def contact_forces(d, np):
    """Normal, tangential force and friction limit; the formulas are in the module docstring."""
    depth = d["depth"]
    chord = d["surface_point"] - d["hip"]
    length = np.linalg.norm(chord, axis=1)
    contact = (d["state"] != 0) & (depth > 0) & (length > 0)
    n = np.full_like(chord, np.nan)
    n[contact] = chord[contact] / length[contact, None]
    force = d["force"]
    f_n = np.where(contact, np.einsum("ij,ij->i", force, np.nan_to_num(n)), 0.0)
    f_t = np.where(contact, np.linalg.norm(force - f_n[:, None] * np.nan_to_num(n), axis=1), 0.0)
    # Free: no normal, and the recorded force is zero; a free finger shows 0 N, no limit.
    free = ~contact
    f_n[free] = 0.0
    f_t[free] = np.linalg.norm(force[free], axis=1)
    mu = np.full(len(depth), np.nan)
    mu[contact] = d["friction_radius"][contact] / depth[contact]
    limit = mu * np.maximum(f_n, 0.0)
    return {"f_n": f_n, "f_t": f_t, "mu": mu, "limit": limit,
            "go_hip": np.linalg.norm(d["god_object"] - d["hip"], axis=1)}


def parse_names(arg):
    return None if arg is None else [s.strip() for s in arg.split(",") if s.strip()]


def select(kind, wanted, available, trace):
    if wanted is None:
        return list(available)
    missing = [n for n in wanted if n not in available]
    if missing:
        raise BadInput(f"{trace.path}: no {kind} named {', '.join(missing)} "
                       f"(the trace has: {', '.join(available) or 'none'})")
    return wanted


def runs(values):
    """(start, end) index pairs of runs of equal value."""
    out, start = [], 0
    for i in range(1, len(values) + 1):
        if i == len(values) or values[i] != values[start]:
            out.append((start, i))
            start = i
    return out


def plot(traces, args, np, plt):
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    a = traces[0]
    objects = select("object", parse_names(args.objects), a.objects, a)
    fingers = select("finger", parse_names(args.fingers), a.fingers, a)
    for b in traces[1:]:
        for kind, names, have in (("object", objects, b.objects), ("finger", fingers, b.fingers)):
            lost = [n for n in names if n not in have]
            if lost:
                print(f"plot_trace: note: {b.path} has no {kind} {', '.join(lost)}", file=sys.stderr)

    t_all = [t for tr in traces for t in (tr.t_physics, tr.t_haptic) if len(t)]
    t_lo = min(float(t[0]) for t in t_all) if t_all else 0.0
    t_hi = max(float(t[-1]) for t in t_all) if t_all else 1.0
    t0 = t_lo if args.t0 is None else args.t0
    t1 = t_hi if args.t1 is None else args.t1
    if not t1 > t0:
        raise BadInput(f"empty time window: --t0 {t0:g} s to --t1 {t1:g} s "
                       f"(the trace spans {t_lo:g} to {t_hi:g} s)")

    finger_colour = {n: plt.cm.tab10(i % 10) for i, n in enumerate(a.fingers)}
    object_colour = {n: plt.cm.Dark2(i % 8) for i, n in enumerate(a.objects)}
    styles = ["-", "--"]
    limit_styles = [":", "-."]
    widths = [1.6, 1.3]
    # With --compare, A is drawn paler underneath and B dashed on top, so both stay visible
    # where they coincide.
    alphas = [0.55, 1.0] if len(traces) > 1 else [1.0]

    band_rows = len(fingers) * len(traces)
    # Layout in inches: title, six time panels, the time axis label, then paths and notes.
    heights = [2.0, 1.5, 1.6, 1.8, 1.6, max(0.6, 0.32 * band_rows + 0.3)]
    top_in, gap_in, bottom_h, bottom_in = 0.6, 0.95, 3.4, 0.55
    total = top_in + sum(heights) + 0.18 * 5 + gap_in + bottom_h + bottom_in
    fig = plt.figure(figsize=(12, total), dpi=100)
    gs = fig.add_gridspec(len(heights), 1, height_ratios=heights, hspace=0.18 * 6 / sum(heights),
                          left=0.09, right=0.80, top=1 - top_in / total,
                          bottom=(bottom_in + bottom_h + gap_in) / total)
    axes = [fig.add_subplot(gs[0])]
    for i in range(1, 6):
        axes.append(fig.add_subplot(gs[i], sharex=axes[0]))
    ax_h, ax_rot, ax_fn, ax_ft, ax_go, ax_band = axes
    low = fig.add_gridspec(1, 2, width_ratios=[1, 1.25], wspace=0.25, left=0.09, right=0.97,
                           top=(bottom_in + bottom_h) / total, bottom=bottom_in / total)
    ax_path = fig.add_subplot(low[0])
    ax_info = fig.add_subplot(low[1])
    # Coinciding curves (a symmetric grasp): earlier fingers drawn wider, so they show round the
    # later ones.
    n_f = max(len(fingers), 1)
    finger_width = {n: 1.4 + 1.1 * (n_f - 1 - i) / max(n_f - 1, 1) if n_f > 1 else 1.6
                    for i, n in enumerate(fingers)}

    def window(t):
        return (t >= t0) & (t <= t1)

    def empty(ax, what):
        ax.set_yticks([])
        ax.text(0.5, 0.5, what, transform=ax.transAxes, ha="center", va="center",
                color="0.4", fontsize=10)

    def legend(ax, handles):
        if handles:
            ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0),
                      fontsize=8.5, frameon=False, borderaxespad=0.0)

    trace_keys = [Line2D([], [], color="0.2", ls=styles[k], lw=widths[k],
                         alpha=alphas[k], label=f"{'AB'[k]}: {tr.label}")
                  for k, tr in enumerate(traces)] if len(traces) > 1 else []

    # Objects: height and rotation.
    for k, tr in enumerate(traces):
        m = window(tr.t_physics)
        for name in objects:
            if name not in tr.object_data:
                continue
            o = tr.object_data[name]
            ax_h.plot(tr.t_physics[m], 1000 * o["position"][m, 2], color=object_colour[name],
                      ls=styles[k], lw=widths[k], alpha=alphas[k])
            ax_rot.plot(tr.t_physics[m], o["angle"][m], color=object_colour[name],
                        ls=styles[k], lw=widths[k], alpha=alphas[k])
    ax_h.set_ylabel("height of the\ncentre of mass z (mm)")
    ax_rot.set_ylabel("rotation from\nfirst pose (deg)")
    obj_keys = [Line2D([], [], color=object_colour[n], lw=2, label=n) for n in objects]
    legend(ax_h, obj_keys + trace_keys)
    lo, hi = ax_rot.get_ylim()
    if hi - lo < 2.0:   # no visible rotation: a 2 degree span, not a magnified rounding error
        ax_rot.set_ylim((lo + hi) / 2 - 1.0, (lo + hi) / 2 + 1.0)
    if not objects:
        empty(ax_h, "no objects in this trace")
        empty(ax_rot, "no objects in this trace")

    # Fingers: forces, |GO - HIP|, stick/slip.
    for k, tr in enumerate(traces):
        m = window(tr.t_haptic)
        t = tr.t_haptic[m]
        for name in fingers:
            if name not in tr.finger_data:
                continue
            d, c = tr.finger_data[name], finger_colour[name]
            lw = finger_width[name] * (1.0 if k == 0 else 0.8)
            ax_fn.plot(t, d["f_n"][m], color=c, ls=styles[k], lw=lw, alpha=alphas[k])
            ax_ft.plot(t, d["f_t"][m], color=c, ls=styles[k], lw=lw, alpha=alphas[k])
            ax_ft.plot(t, d["limit"][m], color=c, ls=limit_styles[k], lw=0.75 * lw,
                        alpha=alphas[k])
            ax_go.plot(t, 1000 * d["go_hip"][m], color=c, ls=styles[k], lw=lw, alpha=alphas[k])
    ax_fn.set_ylabel("normal force\n$f_n$ (N)")
    ax_ft.set_ylabel("tangential force\n$|f_t|$ (N)")
    ax_go.set_ylabel("god-object to HIP\n|GO $-$ HIP| (mm)")
    finger_keys = [Line2D([], [], color=finger_colour[n], lw=2, label=n) for n in fingers]
    legend(ax_fn, finger_keys + trace_keys)
    ft_keys = [Line2D([], [], color="0.2", lw=widths[0], ls=styles[0], label="$|f_t|$"),
               Line2D([], [], color="0.2", lw=1.1, ls=limit_styles[0],
                      label="limit $\\mu f_n$")]
    if len(traces) > 1:
        ft_keys += [Line2D([], [], color="0.2", lw=widths[1], ls=styles[1], label="$|f_t|$ (B)"),
                    Line2D([], [], color="0.2", lw=1.1, ls=limit_styles[1],
                           label="limit $\\mu f_n$ (B)")]
    legend(ax_ft, ft_keys)
    if not fingers:
        for ax in (ax_fn, ax_ft, ax_go):
            empty(ax, "no fingers in this trace")

    # Stick/slip band: one row per finger (and trace), coloured by state, the contacted body
    # written on runs long enough to hold its name.
    labels, dt_h = [], (1.0 / a.rates[1] if a.rates[1] else 0.0)
    row = 0
    for name in fingers:
        for k, tr in enumerate(traces):
            if name not in tr.finger_data:
                continue
            d = tr.finger_data[name]
            t = tr.t_haptic
            step = (1.0 / tr.rates[1]) if tr.rates[1] else dt_h
            y = band_rows - 1 - row
            for s, e in runs(list(zip(d["state"].tolist(), d["body"].tolist()))):
                lo, hi = max(t[s], t0), min(t[e - 1] + step, t1)
                if hi <= lo:
                    continue
                state, body = int(d["state"][s]), int(d["body"][s])
                ax_band.broken_barh([(lo, hi - lo)], (y - 0.4, 0.8),
                                    facecolors=STATE_COLOURS.get(state, "k"), edgecolor="none")
                if state != 0 and (hi - lo) > 0.07 * (t1 - t0):
                    where = ("floor" if body == -2 else
                             tr.body_names[body] if 0 <= body < len(tr.body_names) else "")
                    ax_band.text((lo + hi) / 2, y, where, ha="center", va="center", fontsize=8,
                                 color="white" if state == 2 else "black")
            labels.append((y, name + (f" ({'AB'[k]})" if len(traces) > 1 else "")))
            row += 1
    ax_band.set_yticks([y for y, _ in labels])
    ax_band.set_yticklabels([s for _, s in labels], fontsize=9)
    ax_band.set_ylim(-0.6, max(band_rows, 1) - 0.4)
    ax_band.set_ylabel("contact")
    legend(ax_band, [Patch(color=STATE_COLOURS[s], label=STATE_NAMES[s]) for s in (0, 1, 2)])
    if not fingers:
        ax_band.set_yticks([])
        empty(ax_band, "no fingers in this trace")

    # Forces and distances are never negative: their axes start at 0, so a constant force reads
    # as its value and not as an offset rounding error.
    for ax in (ax_fn, ax_ft, ax_go):
        lo, hi = ax.get_ylim()
        if fingers and lo > -0.05 * hi:
            ax.set_ylim(-0.04 * max(hi, 1e-9), 1.08 * hi)
    for ax in axes:
        if ax is not ax_band:
            ax.ticklabel_format(axis="y", useOffset=False)
        ax.grid(True, color="0.9", lw=0.6)
        ax.set_xlim(t0, t1)
        if ax is not axes[-1]:
            ax.tick_params(labelbottom=False)
    ax_band.grid(False)
    ax_band.set_xlabel("simulated time (s)")

    # Paths of GO (thick) and HIP (thin) in the window, on the two world axes along which they
    # move most.
    pts = []
    for tr in traces:
        m = window(tr.t_haptic)
        for name in fingers:
            if name in tr.finger_data:
                pts += [tr.finger_data[name]["god_object"][m], tr.finger_data[name]["hip"][m]]
    if pts and sum(len(p) for p in pts):
        allp = np.concatenate(pts)
        span = np.nanmax(allp, axis=0) - np.nanmin(allp, axis=0)
        ax0, ax1 = sorted(np.argsort(-np.nan_to_num(span), kind="stable")[:2])
        for k, tr in enumerate(traces):
            m = window(tr.t_haptic)
            for name in fingers:
                if name not in tr.finger_data:
                    continue
                d, c = tr.finger_data[name], finger_colour[name]
                go, hip = 1000 * d["god_object"][m], 1000 * d["hip"][m]
                ax_path.plot(hip[:, ax0], hip[:, ax1], color=c, lw=0.8, ls=styles[k], alpha=0.6)
                ax_path.plot(go[:, ax0], go[:, ax1], color=c, lw=2.0, ls=styles[k])
                if len(go):
                    ax_path.plot(go[0, ax0], go[0, ax1], "o", color=c, ms=4)
        ax_path.set_xlabel(f"world {'xyz'[ax0]} (mm)")
        ax_path.set_ylabel(f"world {'xyz'[ax1]} (mm)")
        ax_path.set_aspect("equal", adjustable="datalim")
        ax_path.grid(True, color="0.9", lw=0.6)
        ax_path.set_title("paths: GO thick, HIP thin, o = start", fontsize=10)
    else:
        ax_path.set_axis_off()
        empty(ax_path, "no finger paths")

    # What was plotted: scenario, status, rates; with --compare, the parameters that differ.
    ax_info.set_axis_off()
    lines = []
    for k, tr in enumerate(traces):
        tag = f"{'AB'[k]}: " if len(traces) > 1 else ""
        lines.append(f"{tag}{tr.path}")
        lines.append(f"    scenario {tr.scenario}, status {tr.status}")
        lines.append(f"    rates {tr.rates[0]} / {tr.rates[1]} / {tr.rates[2]} Hz "
                     "(servo / haptic / physics)")
    if len(traces) > 1:
        pa, pb = set(traces[0].param_lines()), set(traces[1].param_lines())
        diff_a = sorted(pa - pb)
        diff_b = sorted(pb - pa)
        lines.append("parameters that differ:" if diff_a or diff_b else "same parameters")
        for p in diff_a[:6]:
            lines.append(f"    A  {p[:60]}")
        for p in diff_b[:6]:
            lines.append(f"    B  {p[:60]}")
    lines.append("")
    lines.append("normal n = (surface point $-$ HIP) / depth;")
    lines.append("$\\mu$ = friction_radius / depth at each haptic tick")
    ax_info.text(0.0, 1.0, "\n".join(lines), transform=ax_info.transAxes, va="top", ha="left",
                 fontsize=8.5, family="monospace")

    title = a.scenario + (f" vs {traces[1].scenario}" if len(traces) > 1 and
                          traces[1].scenario != a.scenario else "")
    cut = [tr for tr in traces if tr.status != "complete"]
    if cut:
        title += "   (" + "; ".join(f"{tr.label}: status {tr.status}" for tr in cut) + ")"
    fig.suptitle(title, fontsize=13, x=0.09, y=1 - 0.2 / total, ha="left", va="top")
    return fig


def default_out(args):
    stem = os.path.splitext(args.trace)[0]
    if args.compare:
        stem += "_vs_" + os.path.splitext(os.path.basename(args.compare))[0]
    return stem + ".png"


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="plot_trace.py",
        description="Plot a graspsim trace: object height and rotation, finger forces against "
                    "the friction limit, god-object versus HIP, stick/slip, over time.")
    parser.add_argument("trace", metavar="TRACE.h5")
    parser.add_argument("--out", metavar="FIG.png",
                        help="output image (default: TRACE.png next to the trace, or "
                             "TRACE_vs_B.png with --compare)")
    parser.add_argument("--compare", metavar="B.h5",
                        help="overlay a second trace (dashed), aligned by simulated time")
    parser.add_argument("--objects", metavar="A,B", help="objects to plot (default: all)")
    parser.add_argument("--fingers", metavar="A,B", help="fingers to plot (default: all)")
    parser.add_argument("--t0", type=float, metavar="S", help="start of the time window (s)")
    parser.add_argument("--t1", type=float, metavar="S", help="end of the time window (s)")
    args = parser.parse_args(argv)

    try:
        import numpy as np
        import h5py
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as e:
        print(f"plot_trace: {e}: install the Debian packages python3-h5py and "
              "python3-matplotlib and run with /usr/bin/python3", file=sys.stderr)
        return 1

    out = args.out or default_out(args)
    try:
        inputs = [args.trace] + ([args.compare] if args.compare else [])
        for p in inputs:
            if os.path.exists(out) and os.path.exists(p) and os.path.samefile(out, p):
                raise BadInput(f"--out {out} is an input trace; not writing over it")
        if not out.lower().endswith(".png"):
            raise BadInput(f"--out {out}: the output must be a .png file")
        traces = [Trace(p, np, h5py) for p in inputs]
        fig = plot(traces, args, np, plt)
        folder = os.path.dirname(os.path.abspath(out))
        if not os.path.isdir(folder):
            raise BadInput(f"--out {out}: no such directory {folder}")
        # Written to a temporary file and renamed, so a failure leaves no half-written image.
        try:
            fd, tmp = tempfile.mkstemp(suffix=".png", dir=folder)
        except OSError as e:
            raise BadInput(f"--out {out}: cannot write in {folder} ({e.strerror})")
        try:
            with os.fdopen(fd, "wb") as fh:
                fig.savefig(fh, format="png", dpi=100)
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)   # mkstemp's file is private; an image need not be
            os.replace(tmp, out)
        except OSError as e:
            os.unlink(tmp)
            raise BadInput(f"--out {out}: cannot write ({e.strerror})")
    except BadInput as e:
        print(f"plot_trace: {e}", file=sys.stderr)
        return 2
    print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
