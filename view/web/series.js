// The time series the page plots beside the scene, from the blob's columns (view/README.md,
// "Time series"). Pure functions of the recorded values, so the test hook and the plots read the
// same numbers.
//
// Per finger and /haptic row, with F the force on the finger (N), d = SP - HIP (m) and depth = |d|
// as recorded: the face's normal n = d / depth points out of the body (the HIP is inside it), so
//   normal force      f_n = F . d / depth                          (N, > 0 pressing)
//   tangential force  f_t = |F - f_n d / depth|                    (N)
//   friction limit    mu f_n = (friction_radius / depth) f_n       (N; friction_radius = mu depth)
// and 0 for all three while free (depth 0). A sticking finger keeps f_t <= mu f_n; at slip f_t
// meets it.

// Index of the last tick <= t in the sorted `ticks` (0 when t precedes them all).
export function rowAt(ticks, t) {
  let lo = 0, hi = ticks.length - 1;
  if (hi < 0 || t < ticks[0]) return 0;
  while (lo < hi) {
    const mid = (lo + hi + 1) >> 1;
    if (ticks[mid] <= t) lo = mid; else hi = mid - 1;
  }
  return lo;
}

// Normal force, tangential force and friction limit (N) of finger j at /haptic row h.
export function fingerForces(col, j, h) {
  const k = `finger/${j}/`;
  const depth = col[k + 'depth'][h];
  const F = col[k + 'force'], S = col[k + 'surface_point'], P = col[k + 'hip'];
  if (!(depth > 0)) return { fn: 0, ft: 0, limit: 0 };
  const dx = S[3 * h] - P[3 * h], dy = S[3 * h + 1] - P[3 * h + 1], dz = S[3 * h + 2] - P[3 * h + 2];
  const fx = F[3 * h], fy = F[3 * h + 1], fz = F[3 * h + 2];
  const fn = (fx * dx + fy * dy + fz * dz) / depth;
  const tx = fx - fn * dx / depth, ty = fy - fn * dy / depth, tz = fz - fn * dz / depth;
  return { fn, ft: Math.sqrt(tx * tx + ty * ty + tz * tz), limit: col[k + 'friction_radius'][h] / depth * fn };
}

// Every series of a loaded trace, as { ticks, values } (Float64Array each), by name:
// "finger/<j>/fn", "finger/<j>/ft", "finger/<j>/limit" (N), "finger/<j>/state" (0, 1, 2) on the
// /haptic ticks; "body/<i>/height" (m, the centre of mass's z) and "body/<i>/torsion" (N m) on
// the /physics ticks.
export function allSeries(scene, col) {
  const out = {};
  const nh = col.haptic_tick.length;
  scene.fingers.forEach((f, j) => {
    const fn = new Float64Array(nh), ft = new Float64Array(nh), limit = new Float64Array(nh);
    for (let h = 0; h < nh; h++) {
      const v = fingerForces(col, j, h);
      fn[h] = v.fn; ft[h] = v.ft; limit[h] = v.limit;
    }
    out[`finger/${j}/fn`] = { ticks: col.haptic_tick, values: fn };
    out[`finger/${j}/ft`] = { ticks: col.haptic_tick, values: ft };
    out[`finger/${j}/limit`] = { ticks: col.haptic_tick, values: limit };
    out[`finger/${j}/state`] = { ticks: col.haptic_tick, values: Float64Array.from(col[`finger/${j}/state`]) };
  });
  scene.bodies.forEach((b, i) => {
    const p = col[`body/${i}/position`], n = col.physics_tick.length, z = new Float64Array(n);
    for (let r = 0; r < n; r++) z[r] = p[3 * r + 2];
    out[`body/${i}/height`] = { ticks: col.physics_tick, values: z };
    out[`body/${i}/torsion`] = { ticks: col.physics_tick, values: col[`body/${i}/torsion`] };
  });
  return out;
}

// The value of series `s` at servo tick t: its last row at or before t.
export const valueAt = (s, t) => s.values[rowAt(s.ticks, t)];
