"""One study's merged analysis against another's (tests/server/study_test.py,
tests/deploy/slurm_test.py): the same groups, configurations, samples and points, and each
figure within its tolerance. Samples that ran uninterrupted are bit-identical (same twin, same
seed); a resumed sample's points after the interruption start from standstill on a fresh twin,
so they agree to the noise."""

# The plan both tests run: 4 Ld values x 2 Rs values = 8 samples of 2 configurations x 3 angles.
PLAN = {
    "name": "ld-rs",
    "sweep": {"name": "s", "window_s": 0.2, "thermal": {"enabled": False},
              "dimensions": {"speed_rpm": [700], "load_Nm": [1.0], "angle_deg": [50, 56, 62],
                             "configurations": [{"estimator": "encoder", "pwm": "capwm"},
                                                {"estimator": "eemf-lut", "pwm": "capwm"}]}},
    "grid": {"ld_pct": [-25, -10, 0, 25], "rs_pct": [0, 20]},
}
SAMPLES, POINTS_PER_SAMPLE = 8, 6

TOLERANCE = {"pos_err_abs_mean_deg": 0.3, "pos_err_abs_max_deg": 3.0, "speed_err_abs_mean_rpm": 3.0,
             "efficiency_mean": 0.003, "mtpa_angle_mean_deg": 1.0, "mtpa_shift_deg": 1.0}


def cells(analysis):
    """{(parameter, group's from, configuration): figures} of `synbench study analyse --json-out`."""
    out = {}
    for p in analysis["parameters"]:
        for g in p["groups"]:
            for c in g["configurations"]:
                out[(p["parameter"], g["from"], c["configuration"])] = c
    return out


def compare(check, ref, other, label):
    """Checks `other` (a merged analysis) against `ref` (an uninterrupted run's)."""
    check(other["points"] == ref["points"] == SAMPLES * POINTS_PER_SAMPLE, f"[{label}] merged points ({other['points']})")
    a, b = cells(ref), cells(other)
    check(a.keys() == b.keys(), f"[{label}] same groups and configurations")
    worst = {}
    for k in a.keys() & b.keys():
        check(a[k]["samples"] == b[k]["samples"] and a[k]["points"] == b[k]["points"], f"[{label}] {k}: same samples and points")
        for f in TOLERANCE:
            if a[k][f] is None or b[k][f] is None:
                check(a[k][f] is None and b[k][f] is None, f"[{label}] {k} {f}: both null")
                continue
            worst[f] = max(worst.get(f, 0), abs(a[k][f] - b[k][f]))
    for f, t in TOLERANCE.items():
        check(worst.get(f, 0) <= t, f"[{label}] merged {f} matches the uninterrupted run within {t} (worst {worst.get(f, 0):.4g})")
