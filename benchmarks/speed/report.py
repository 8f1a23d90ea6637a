"""The text report: aligned tables of the JSON result (times in us, median and p10-p90)."""

from __future__ import annotations

from typing import Any

from benchmarks.speed.pipeline import PIPELINE_STAGES

__all__ = ["baseline_text", "fmt_us", "table", "text_report"]


def fmt_us(s: dict[str, float] | None, spread: bool = True) -> str:
    if not s:
        return "-"
    m = s["median"]
    core = f"{m:.0f}" if m >= 100 else f"{m:.1f}"
    if spread and "p10" in s:
        return (
            f"{core} ({s['p10']:.0f}-{s['p90']:.0f})"
            if m >= 100
            else f"{core} ({s['p10']:.1f}-{s['p90']:.1f})"
        )
    return core


def table(headers: list[str], rows: list[list[str]]) -> str:
    widths = [
        max(len(h), *(len(r[i]) for r in rows)) if rows else len(h) for i, h in enumerate(headers)
    ]

    def line(cells: list[str]) -> str:
        return "  ".join(
            c.rjust(w) if i else c.ljust(w)
            for i, (c, w) in enumerate(zip(cells, widths, strict=True))
        )

    return "\n".join([line(headers), line(["-" * w for w in widths])] + [line(r) for r in rows])


def text_report(result: dict[str, Any], args) -> str:
    out = []
    m = result["machine"]
    out.append(
        f"Machine: {m['cpu']}, {m['cpu_count']} CPUs; {m['platform']}; Python {m['python']}; "
        f"load average {' '.join(map(str, m.get('load_average_before', [])))} at the start"
    )
    out.append(
        "Versions: "
        + ", ".join(f"{k} {v}" for k, v in m["versions"].items())
        + f"; pypoman LP solver: {m.get('pypoman_lp_solver')}"
    )
    s = result["settings"]
    out.append(
        f"Repeats: {s['repeat']} (cheap calls {s['repeat_cheap']}), warm-up {s['warmup']}; times "
        "in us, median (p10-p90)"
    )
    out.append("")
    out.append(
        "1. Projection (resultant horizontal force polygon, units of m g): ours (compiled walk) "
        f"vs pypoman bretl (onto {s['pypoman_scale']:g} F) and vs our own Bretl/HiGHS path; "
        f"agreement = relative area of the symmetric difference, tol {s['tol']:g}, with both"
    )
    rows = []
    for name, e in result["stances"].items():
        p = e["projection"]
        rows.append(
            [
                name,
                e["robot"],
                str(e["n_contacts"]),
                str(p["n_ineq"]),
                str(p["pivots"]),
                str(p["n_vertices"]),
                fmt_us(p["project_us"]),
                fmt_us(p.get("pypoman_us")),
                f"{p['ratio_vs_pypoman']:.1f}" if "ratio_vs_pypoman" in p else "-",
                fmt_us(p["bretl_highs_us"], False),
                f"{p['ratio_vs_bretl_highs']:.1f}",
                f"{p['area_rel_diff']:+.1e}" if "area_rel_diff" in p else "-",
                f"{p['symdiff_rel']:.1e}" if "symdiff_rel" in p else "-",
                ("ok" if p.get("match") else "MISMATCH") if "match" in p else "-",
            ]
        )
    out.append(
        table(
            [
                "stance",
                "robot",
                "contacts",
                "ineq rows",
                "pivots",
                "verts",
                "ours us",
                "pypoman us",
                "ratio",
                "bretl/HiGHS us",
                "ratio",
                "area rel diff",
                "symdiff",
                "check",
            ],
            rows,
        )
    )
    out.append("")
    out.append(
        "2. Pipeline per stage (median us; analyze() = whole pipeline end to end, YAML excluded)"
    )
    rows = []
    for name, e in result["stances"].items():
        p = e["pipeline"]
        rows.append(
            [name]
            + [fmt_us(p.get(k), False) for k in PIPELINE_STAGES]
            + [fmt_us({"median": p["sum_of_stages"]["median"]}, False), fmt_us(p["analyze"])]
        )
    out.append(table(["stance", *PIPELINE_STAGES, "sum", "analyze (p10-p90)"], rows))
    out.append("")
    out.append("3. Maximum contact velocity given the area")
    rows = []
    for name, e in result["stances"].items():
        mv = e.get("max_velocity")
        if mv:
            v = e["pipeline"].get("max_contact_velocity_m_s")
            rows.append(
                [
                    name,
                    str(mv["area_edges"]),
                    fmt_us(mv["max_velocity"]),
                    fmt_us(mv["zmp_max_velocity"]),
                    "inf" if v is None else f"{v:.4f}",
                ]
            )
    out.append(
        table(
            [
                "stance",
                "area edges",
                "max_contact_velocity us",
                "zmp_max_contact_velocity us",
                "answer m/s",
            ],
            rows,
        )
    )
    sc = result.get("scaling")
    if sc:
        out.append("")
        out.append("4a. Scaling with contacts (Talos, configuration of talos_three_contacts)")
        rows = []
        for e in sc["contacts"]:
            rows.append(
                [
                    e["contacts"],
                    "yes" if e["torque_limits"] else "no",
                    str(e["n_ineq"]),
                    str(e["pivots"]),
                    str(e["n_vertices"]),
                    fmt_us(e["stance_us"], False),
                    fmt_us(e["constraints_us"], False),
                    fmt_us(e["project_us"]),
                    fmt_us(e.get("pypoman_us")),
                    f"{e['ratio_vs_pypoman']:.1f}" if "ratio_vs_pypoman" in e else "-",
                    f"{e['symdiff_rel']:.1e}" if "symdiff_rel" in e else "-",
                    ("ok" if e.get("match") else "MISMATCH") if "match" in e else "-",
                ]
            )
        out.append(
            table(
                [
                    "contacts",
                    "torque lim",
                    "ineq rows",
                    "pivots",
                    "verts",
                    "Stance us",
                    "constraints us",
                    "ours us",
                    "pypoman us",
                    "ratio",
                    "symdiff",
                    "check",
                ],
                rows,
            )
        )
        out.append("")
        out.append("4b. Scaling with friction-cone edges of the impact (median us)")
        rows = [
            [
                e["scenario"],
                str(e["cone_edges"]),
                fmt_us(e["impact_model_us"]),
                fmt_us(e["max_velocity_us"]),
                fmt_us(e["zmp_max_velocity_us"]),
                "inf"
                if e["max_contact_velocity_m_s"] is None
                else f"{e['max_contact_velocity_m_s']:.4f}",
            ]
            for e in sc["cone_edges"]
        ]
        out.append(
            table(
                [
                    "stance",
                    "edges",
                    "impact_model",
                    "max_velocity",
                    "zmp_max_velocity",
                    "answer m/s",
                ],
                rows,
            )
        )
    out.append("")
    out.append("Targets (informative; they do not change the exit status)")
    for t in result["targets"]:
        out.append(f"  [{'PASS' if t['pass'] else 'FAIL'}] {t['target']}: {t['measured']}")
    c = result["checks"]
    out.append("")
    if c["ok"]:
        out.append(
            f"Answers: OK, every pypoman and Bretl/HiGHS polygon matches ours within {s['tol']:g} "
            f"relative area (worst symmetric difference {c['worst_symdiff_rel']:.1e})."
        )
    else:
        out.append("Answers: MISMATCH")
        for f in c["failures"]:
            out.append(f"  {f}")
    return "\n".join(out)


def baseline_text(side: dict[str, Any]) -> str:
    """Part 5 (``--baseline``): current and baseline interleaved, ratios current / baseline."""
    rows = []
    for name, entry in side["stances"].items():
        for i, (case, q) in enumerate(entry["cases"].items()):
            r = q["ratio"]["median"]
            rows.append(
                [
                    name if i == 0 else "",
                    case,
                    fmt_us(q["current"], spread=False),
                    fmt_us(q["baseline"], spread=False),
                    "-"
                    if r["median"] is None
                    else f"{r['median']:.2f} [{r['low']:.2f}-{r['high']:.2f}]",
                    ("yes" if entry["same_answer"] else "NO") if i == 0 else "",
                ]
            )
    coverage = min(
        (
            q["ratio"]["median"]["coverage"]
            for e in side["stances"].values()
            for q in e["cases"].values()
        ),
        default=0.0,
    )
    low, high = side["load_average_1min_range"]
    head = (
        f"5. Side by side, interleaved: current {side['trees']['current']} / baseline "
        f"{side['trees']['baseline']}\n"
        f"{side['blocks']} alternating blocks per side; load average (1 min) {low:.2f} to "
        f"{high:.2f} over the blocks; median us over all blocks; ratio = current / baseline, "
        f"median of the per-block ratios [interval over blocks, coverage >= {coverage:.0%}]"
    )
    headers = ["stance", "case", "current us", "baseline us", "ratio [interval]", "same answer"]
    return head + "\n" + table(headers, rows)
