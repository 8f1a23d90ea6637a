#!/usr/bin/env bash
# The id QP's inertia with MuJoCo's implicit damping (after the fact, spent stances):
# docs/studies/hand-contacts.md. One command at a time; each answer appended to
# studies/implicit_damping/results.jsonl as it ends. From the repository root:
#   LABEL=with bash studies/implicit_damping/run.sh KIND FILE...
# KIND: rigid | free (validate --controller id [--rigid-impact] --tolerance $TOL --max-speed 4)
#       approach (approach --governor com --reference 0.8 --wall-distance-range 0.10 0.20: 3 trials)
# The set's scoring flags: sets 11 and 12 add --friction-scale controller, set 12's validate
# --impact-model held-stance (its protocol, /work/runs/heldout12/job.sh).
set -u
out=studies/implicit_damping/results.jsonl
TOL=${TOL:-0.1}
LABEL=${LABEL:-with}
kind=$1; shift
tmp=$(mktemp)
flags_for() {
  local f="--angular-momentum-damping-time controller --com-reach"
  case "$1" in
    *held_out_11/*) f="$f --friction-scale controller" ;;
    *held_out_12/*) f="$f --friction-scale controller"
      [ "$kind" != approach ] && f="$f --impact-model held-stance" ;;
  esac
  echo "$f"
}
for f in "$@"; do
  start=$(date +%s)
  case $kind in
    rigid) cmd="validate $f --controller id --rigid-impact --tolerance $TOL --max-speed 4 --no-journal" ;;
    free) cmd="validate $f --controller id --tolerance $TOL --max-speed 4 --no-journal" ;;
    approach) cmd="approach $f --governor com --reference 0.8 --wall-distance-range 0.10 0.20" ;;
  esac
  # shellcheck disable=SC2046,SC2086
  nice -n 5 impact-balance $cmd $(flags_for "$f") --json > "$tmp" 2>/dev/null
  rc=$?
  python - "$f" "$kind" "$LABEL" "$rc" "$(( $(date +%s) - start ))" "$(cut -d' ' -f1 /proc/loadavg)" "$tmp" "$TOL" "$(git rev-parse --short HEAD)" >> "$out" <<'PY'
import json, sys
f, kind, label, rc, wall, load, path, tol, commit = sys.argv[1:]
row = {"stance": f, "kind": kind, "label": label, "rc": int(rc), "wall_s": int(wall),
       "load1": float(load), "commit": commit}
try:
    d = json.load(open(path))
except Exception:
    d = None
if d and kind == "approach":
    row.update(trials=[{k: t.get(k) for k in ("wall_distance", "speed_at_contact", "cap_at_contact",
                        "outcome", "strict_fail", "strict_reason", "detail")} for t in d["trials"]])
elif d:
    e, p = d["empirical"], d["predicted"]
    row.update(
        tolerance=float(tol), survived=e.get("survived"), fell=e.get("fell"),
        strict_failed=e.get("strict_failed"), strict_stood=e.get("strict_stood"),
        first_contact_break=(e.get("first_contact_break") or {}).get("measured"),
        predicted_default=p.get("default"),
        predicted_within_reach=(d.get("verdict") or {}).get("predicted"),
        verdict=(d.get("verdict") or {}).get("verdict"),
        trials=[[t["speed"], t["approach_speed_measured"], t["outcome"], t["strict_fail"],
                 t.get("strict_reason")] for t in d.get("trials", [])],
        implicit_damping_inertia=d["controller"]["gains"].get("implicit_damping_inertia"),
    )
print(json.dumps(row))
PY
  tail -1 "$out" | cut -c1-300
done
rm -f "$tmp"
