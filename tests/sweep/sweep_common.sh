# Shared by the sweep tests (sourced): the 3 x 3 x 2 sweep and how tables are compared.
# The sweep: the two-finger lift (scenarios/two_finger_lift.lua, 4 s, about 15 ms of CPU a run
# without a trace) over the box's friction coefficient mu, its mass (kg) and 2 seeds of
# +-0.5 mm jittered waypoints. Each finger presses N = k d = 400 N/m x 0.01 m = 4 N, so the
# lift holds when 2 mu N > m g, i.e. mu > m g / (8 N): 0.25, 0.49 and 0.98 for 0.2, 0.4 and
# 0.8 kg. Hence the expected status by (mu, mass), the same for both seeds, and every failure
# one where the box is not lifted (it stays on the floor while the fingers slide up it):
#   mu 0.2: fail at every mass (0.2 < 0.25);
#   mu 0.6: pass at 0.2 and 0.4 kg, fail at 0.8 kg (0.6 < 0.98);
#   mu 1.2: pass at every mass (1.2 > 0.98, a margin of 1.2 at 0.8 kg).
sweep_grid=(--grid mu=0.2,0.6,1.2 --grid mass=0.2,0.4,0.8 --seeds 2)
sweep_expected='0.2,0.2 fail
0.2,0.4 fail
0.2,0.8 fail
0.6,0.2 pass
0.6,0.4 pass
0.6,0.8 fail
1.2,0.2 pass
1.2,0.4 pass
1.2,0.8 pass'

fail() { echo "FAIL: $*"; exit 1; }

# The table without its wall_s column (the one column that depends on the machine's load).
table_without_wall() {
  /usr/bin/python3 - "$1" <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1], newline="")))
w = rows[0].index("wall_s")
for r in rows:
    print(",".join(r[:w] + r[w + 1:]))
PY
}

# "mu,mass status" for each grid point, with both seeds' status equal (else "mixed"), and
# "lifted" where a failing run's box was lifted after all (its failure is not the friction's).
status_by_point() {
  /usr/bin/python3 - "$1" <<'PY'
import csv, sys
points = {}
for r in csv.DictReader(open(sys.argv[1], newline="")):
    points.setdefault((r["mu"], r["mass"]), set()).add(
        "lifted" if r["status"] == "fail" and r["pass: the box is lifted at least 5 cm"] != "0" else r["status"])
for (mu, mass), s in points.items():
    print(f"{mu},{mass} {s.pop() if len(s) == 1 else 'mixed'}")
PY
}
