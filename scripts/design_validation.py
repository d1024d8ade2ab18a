#!/usr/bin/env python3
"""Predicted against realised standard errors (scripts/design_validation.sh).

Usage: design_validation.py OUT SEED...

Reads OUT/design/design.json (the predictions) and the fits OUT/paper_s<seed>
and OUT/proposed_s<seed> (fit.json each), and prints per plan and parameter:
the predicted standard error, the mean of those the fits reported, the
spread (sample standard deviation) of the estimates over the seeds, the
largest error to the truth and whether every 95 % interval covered it.
Writes the same table to OUT/validation.md.
"""
import json
import math
import os
import sys

def load(path):
    with open(path) as f:
        return json.load(f)


def truth_of(fit):
    """The true parameters of a fit's recordings: the `parameters:` block of
    the first experiment's <stem>.truth.yaml (ccsrm generate)."""
    path = os.path.splitext(fit["experiments"][0]["path"])[0] + ".truth.yaml"
    values, inside = {}, False
    with open(path) as f:
        for line in f:
            if line.startswith("parameters:"):
                inside = True
            elif inside and line.startswith("  ") and ":" in line:
                name, value = line.split("#")[0].split(":", 1)
                values[name.strip()] = float(value)
            elif inside and line.strip():
                break
    return values


def main():
    out, seeds = sys.argv[1], sys.argv[2:]
    design = load(os.path.join(out, "design", "design.json"))
    proposed = next(
        design["candidates"][k]
        for k in design["ranking"]
        if design["candidates"][k]["protocol_yaml"] and design["candidates"][k]["completed"]
    )
    paper = next(c for c in design["candidates"] if not c["protocol_yaml"])
    lines = [
        "noise of the prediction: %.4f deg per angle, N_eff/N %.4f (from paper_s1's fit)"
        % (design["noise_deg"], design["effective_sample_fraction"]),
        "",
    ]
    worst = {}
    for label, stem, plan in (("paper", "paper", paper), ("proposed", "proposed", proposed)):
        fits = []
        for seed in seeds:
            path = os.path.join(out, "%s_s%s" % (stem, seed), "fit.json")
            if os.path.exists(path):
                fits.append((seed, load(path)))
        lines.append(
            "%s plan: %s (%.0f s), %d fits (seeds %s)"
            % (label, plan["name"], plan["duration_s"], len(fits), " ".join(s for s, _ in fits))
        )
        lines.append(
            "| parameter | predicted SE | reported SE (mean over seeds) | ratio | spread of estimates"
            " | ratio | largest error to truth | intervals covering |"
        )
        lines.append("|---|---|---|---|---|---|---|---|")
        worst[label] = 0.0
        for p in plan["parameters"]:
            name = p["name"]
            predicted = p["std_error"]
            reported, estimates, covered, errors = [], [], 0, []
            for _, fit in fits:
                truth = truth_of(fit)[name]
                e = fit["parameters"][name]
                estimates.append(e["value"])
                errors.append(abs(e["value"] - truth) / truth)
                if e.get("std_error") is not None:
                    reported.append(e["std_error"])
                    lo, hi = e["ci95"]
                    covered += lo <= truth <= hi
            mean_reported = sum(reported) / len(reported) if reported else float("nan")
            n = len(estimates)
            mean = sum(estimates) / n if n else float("nan")
            spread = (
                math.sqrt(sum((x - mean) ** 2 for x in estimates) / (n - 1)) if n > 1 else float("nan")
            )
            rel = p["relative_std_error"] if p["relative_std_error"] is not None else float("inf")
            worst[label] = max(worst[label], rel)
            fmt = lambda x: "%.4g" % x if x is not None and math.isfinite(x) else "-"
            lines.append(
                "| %s | %s (%.3g %%) | %s | %s | %s | %s | %.3g %% | %d of %d |"
                % (
                    name,
                    fmt(predicted),
                    100 * rel,
                    fmt(mean_reported),
                    fmt(mean_reported / predicted) if predicted else "-",
                    fmt(spread),
                    fmt(spread / predicted) if predicted else "-",
                    100 * max(errors) if errors else float("nan"),
                    covered,
                    n,
                )
            )
        lines.append("")
    if worst.get("proposed"):
        lines.append(
            "worst predicted relative standard error: paper %.3g %%, proposed %.3g %%: %.0f times smaller"
            % (100 * worst["paper"], 100 * worst["proposed"], worst["paper"] / worst["proposed"])
        )
    corner = os.path.join(out, "corner", "fit.json")
    if os.path.exists(corner):
        fit = load(corner)
        truth = truth_of(fit)
        lines.append("")
        lines.append(
            "truth at a corner of the prior box (%s), proposed plan, one recording:"
            % ", ".join("%s = %g" % (b["name"], truth[b["name"]]) for b in design["prior_box"])
        )
        lines.append("| parameter | truth | estimate | error | reported SE | 95 % interval covers |")
        lines.append("|---|---|---|---|---|---|")
        for name in design["free_parameters"]:
            e = fit["parameters"][name]
            se = e.get("std_error")
            covers = se is not None and e["ci95"][0] <= truth[name] <= e["ci95"][1]
            lines.append(
                "| %s | %g | %.6g | %.3g %% | %s | %s |"
                % (
                    name,
                    truth[name],
                    e["value"],
                    100 * (e["value"] - truth[name]) / truth[name],
                    "%.3g (%.3g %%)" % (se, 100 * se / truth[name]) if se is not None else "-",
                    "yes" if covers else "no",
                )
            )
    text = "\n".join(lines) + "\n"
    sys.stdout.write(text)
    with open(os.path.join(out, "validation.md.tmp"), "w") as f:
        f.write(text)
    os.replace(os.path.join(out, "validation.md.tmp"), os.path.join(out, "validation.md"))


if __name__ == "__main__":
    main()
