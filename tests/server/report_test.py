#!/usr/bin/env python3
"""The one-click report (docs/report.md) against the real `synbench sweep`, `synbench report` and
`synbench serve`: a two-configuration sweep into a temporary database; the report's HTML is
self-contained (no script, no external src/href), has one inline SVG per figure the analysis
has data for, each titled with the sweep and its configuration; its MTPA/ME table and efficiency
grids equal the daemon's analysis JSON to the printed precision; the CSV beside it has every
stored point; the daemon's GET /api/sweeps/{id}/report and report.csv give the same bytes as the
command line (modulo the generation time); clear errors for an unknown sweep, no database, a bad
id. Uncertainty (issue 26): the optima's +/- u columns and ME - MTPA significance, the deltas and
the efficiency u grids equal the analysis JSON; one error bar per known u with its value; the
uncertainty section's counts; a sweep with its points' u cleared says "No uncertainty stored".
Standard library only.

usage: report_test.py path/to/synbench
"""
import csv
import html.parser
import io
import math
import os
import re
import sqlite3
import subprocess
import sys
import tempfile

from checks import Checks
from daemon import Daemon, run_sweep

BIN = sys.argv[1]
check = Checks(verbose=False)


class Page(html.parser.HTMLParser):
    """Tags with their attributes, SVG titles, and the text of every table's cells by table id/class."""

    def __init__(self):
        super().__init__()
        self.tags, self.svg_titles, self.tables = [], [], []
        self._in_svg_title = self._svg_depth = 0
        self._table = self._row = self._cell = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        self.tags.append((tag, a))
        if tag == "svg":
            self._svg_depth += 1
            self.svg_titles.append("")
        elif tag == "title" and self._svg_depth:
            self._in_svg_title = True
        elif tag == "table":
            self._table = {"id": a.get("id"), "class": a.get("class"), "attrs": a, "rows": []}
            self.tables.append(self._table)
        elif tag == "tr" and self._table is not None:
            self._row = []
            self._table["rows"].append(self._row)
        elif tag in ("td", "th") and self._row is not None:
            self._cell = ""

    def handle_endtag(self, tag):
        if tag == "svg":
            self._svg_depth -= 1
        elif tag == "title":
            self._in_svg_title = False
        elif tag in ("td", "th") and self._cell is not None:
            self._row.append(self._cell.strip())
            self._cell = None
        elif tag == "table":
            self._table = None

    def handle_data(self, data):
        if self._in_svg_title:
            self.svg_titles[-1] += data
        if self._cell is not None:
            self._cell += data


def parse(text):
    p = Page()
    p.feed(text)
    return p


def expected_figures(a):
    """One figure per: efficiency map and contour map (each contour entry), trajectory plot per
    configuration with curves, I_m and P_dcM per (configuration, speed), position error per
    configuration with entries, the two delta plots per configuration with deltas, each histogram."""
    cfg = lambda e: (e["estimator"], e["pwm"])
    curves = a["curves"]["entries"]
    n = 2 * len(a["efficiency_contours"]["entries"])
    n += len({cfg(c) for c in curves})
    n += 2 * len({(cfg(c), c["speed_rpm"]) for c in curves})
    n += len({cfg(p) for p in a["position_error"]["entries"]})
    n += 2 * len({cfg(d) for d in a["deltas"]["entries"]})
    n += len(a["histograms"]["entries"])
    return n


def g(v):
    return "%g" % v


def fixed(v, d):
    return "–" if v is None else "%.*f" % (d, v)


def u_text(u):
    """A standard uncertainty as the report prints it: two significant digits, "–" unknown."""
    if u is None:
        return "–"
    if u == 0:
        return "0"
    return "%.*f" % (min(max(0, 1 - math.floor(math.log10(u))), 8), u)


def sig(s):
    return "–" if s is None else ("yes" if s else "no")


def main():
    tmp = tempfile.mkdtemp(prefix="synbench-report-")
    data = os.path.join(tmp, "data")
    os.makedirs(data)
    db = os.path.join(data, "synbench.db")
    plan = {"name": "Report test: encoder vs EKF", "window_s": 0.5,
            "dimensions": {"speed_rpm": [500, 900], "load_Nm": [1, 2, 3], "angle_deg": {"from": 42, "to": 66, "step": 4},
                           "configurations": [{"estimator": "encoder", "pwm": "capwm"},
                                              {"estimator": "ekf-basic", "pwm": "aspwm"}]}}
    r = run_sweep(BIN, plan, db, tmp, "--quiet", timeout=300)
    check(r.returncode == 0, "the sweep ran (%s)" % r.stderr[-300:])

    # Errors.
    r = subprocess.run([BIN, "report", "7", "--db", db, "--out", tmp], capture_output=True, text=True)
    check(r.returncode == 1 and "sweep 7" in r.stderr, "an unknown sweep: exit 1 naming it (%d %r)" % (r.returncode, r.stderr))
    r = subprocess.run([BIN, "report", "1", "--db", os.path.join(tmp, "none.db")], capture_output=True, text=True)
    check(r.returncode == 2 and "--db" in r.stderr and "none.db" in r.stderr, "no database: exit 2 naming --db (%r)" % r.stderr)
    check(not os.path.exists(os.path.join(tmp, "none.db")), "no database is created by report")
    r = subprocess.run([BIN, "report", "x1", "--db", db], capture_output=True, text=True)
    check(r.returncode == 2 and "SWEEP_ID" in r.stderr, "a bad id: exit 2 (%r)" % r.stderr)
    r = subprocess.run([BIN, "--help"], capture_output=True, text=True)
    check("report" in r.stdout, "synbench --help lists report")

    out = os.path.join(tmp, "out")
    r = subprocess.run([BIN, "report", "1", "--db", db, "--out", out], capture_output=True, text=True, timeout=120)
    check(r.returncode == 0, "report wrote (%s)" % r.stderr)
    paths = r.stdout.split()
    check(len(paths) == 2, "two paths printed: %r" % r.stdout)
    html_path, csv_path = paths[0], paths[1]
    check(re.fullmatch(r".*/synbench-report-1-report-test-encoder-vs-ekf-\d{4}-\d{2}-\d{2}\.html", html_path),
          "the HTML name: %s" % html_path)
    check(csv_path == html_path[:-5] + ".csv", "the CSV beside it: %s" % csv_path)
    page_text = open(html_path, encoding="utf-8").read()
    csv_text = open(csv_path, encoding="utf-8").read()

    d = Daemon(BIN, data)
    try:
        st, analysis = d.request("GET", "/api/sweeps/1/analysis")
        check(st == 200, "analysis 200")
        st, sweep = d.request("GET", "/api/sweeps/1")
        st, points = d.request("GET", "/api/sweeps/1/points")
        status, body, resp = d.http("GET", "/api/sweeps/1/report", token=d.operator, timeout=60)
        check(status == 200 and resp.getheader("Content-Type", "").startswith("text/html"), "report route: 200 text/html")
        disp = resp.getheader("Content-Disposition", "")
        check(disp == 'attachment; filename="%s"' % os.path.basename(html_path), "Content-Disposition: %r" % disp)
        strip = lambda t: re.sub(r"<time>[^<]*</time>", "<time/>", t)
        check(strip(body.decode()) == strip(page_text), "the daemon's report is the CLI's (modulo the generation time)")
        status, body, resp = d.http("GET", "/api/sweeps/1/report.csv", token=d.token("viewer"))
        check(status == 200 and body.decode() == csv_text, "report.csv (as a viewer) is the CLI's CSV")
        check(resp.getheader("Content-Disposition", "").endswith(os.path.basename(csv_path) + '"'), "report.csv's file name")
        st, _ = d.request("GET", "/api/sweeps/9/report")
        check(st == 404, "report of an unknown sweep: 404 (%s)" % st)
        st, openapi = d.request("GET", "/api/openapi.json")
        check("/api/sweeps/{id}/report" in openapi.get("paths", {}) and
              "text/html" in openapi["paths"]["/api/sweeps/{id}/report"]["get"]["responses"]["200"]["content"],
              "the report route is in the OpenAPI document as text/html")
    finally:
        d.stop()

    p = parse(page_text)
    # Self-contained: no script, no external resource.
    for tag, a in p.tags:
        check(tag not in ("script", "link", "img", "iframe", "object"), "no <%s>" % tag)
        for k in ("src", "href"):
            if k in a:
                check(a[k].startswith("#"), "no external %s: %s=%r" % (k, k, a[k]))
    check(len(page_text) > 20000, "the report has substance (%d bytes)" % len(page_text))
    want = expected_figures(analysis)
    check(len(p.svg_titles) == want, "%d SVG figures, expected %d" % (len(p.svg_titles), want))
    check(page_text.count("<svg") == want, "<svg count")
    for t in p.svg_titles:
        check("sweep #1 'Report test: encoder vs EKF'" in t and re.search(r"(encoder/capwm|ekf-basic/aspwm)", t),
              "figure title names the sweep and its configuration: %r" % t)
    check(any("contours" in t for t in p.svg_titles), "a contour figure")
    check(page_text.count('class="iso"') >= sum(len(e["lines"]) for e in analysis["efficiency_contours"]["entries"]) > 0,
          "every iso-line drawn")

    # The MTPA/ME table equals the analysis to the printed precision.
    optima = [t for t in p.tables if t["id"] == "optima"]
    check(len(optima) == 1, "one optima table")
    rows = {tuple(r[:4]): r for r in optima[0]["rows"][1:]}
    curves = analysis["curves"]["entries"]
    check(len(rows) == len(curves) > 0, "one row per curve (%d, %d)" % (len(rows), len(curves)))
    for c in curves:
        row = rows.get((c["estimator"], c["pwm"], g(c["speed_rpm"]), g(c["load_Nm"])))
        if not check(row is not None, "a row for %r" % c):
            continue
        want_cells = [str(c["points"])]
        for o in (c["mtpa"], c["me"]):
            want_cells += [fixed(o["angle_deg"], 2), fixed(o["im_A"], 3), fixed(o["pdcm_W"], 1), fixed(o["efficiency"], 4)]
        check(row[4:13] == want_cells, "optima of %s/%s %s rpm %s N m: %r == %r" %
              (c["estimator"], c["pwm"], c["speed_rpm"], c["load_Nm"], row[4:13], want_cells))
        want_u = [u_text(c["mtpa_angle_u_deg"]), u_text(c["mtpa"]["im_u_A"]), u_text(c["me_angle_u_deg"]),
                  u_text(c["me"]["pdcm_u_W"]), u_text(c["me"]["efficiency_u"]), fixed(c["me_minus_mtpa_deg"], 2),
                  u_text(c["me_minus_mtpa_u_deg"]), sig(c["me_minus_mtpa_significant"])]
        check(row[13:] == want_u, "optima's u and ME - MTPA significance of %s/%s %s rpm %s N m: %r == %r" %
              (c["estimator"], c["pwm"], c["speed_rpm"], c["load_Nm"], row[13:], want_u))
    check(sum(1 for c in curves if c["mtpa_angle_u_deg"] is not None and c["me"]["pdcm_u_W"] is not None) >= len(curves) // 2,
          "the twin sweep's curves have their uncertainties (so the columns above are numbers)")
    # The deltas with u and significance.
    dt = [t for t in p.tables if t["id"] == "deltas"]
    des = analysis["deltas"]["entries"]
    if check(len(dt) == 1 and len(dt[0]["rows"]) - 1 == len(des) > 0, "one deltas table, a row per delta"):
        for row, d in zip(dt[0]["rows"][1:], des):
            want_cells = [d["estimator"], d["pwm"], g(d["speed_rpm"]), g(d["load_Nm"])]
            for o, q, dec in (("mtpa", "angle", 2), ("mtpa", "im", 3), ("me", "angle", 2), ("me", "pdcm", 2)):
                unit = {"angle": "deg", "im": "A", "pdcm": "W"}[q]
                t = d[o]
                want_cells += [fixed(t["delta_%s_%s" % (q, unit)], dec), u_text(t["delta_%s_u_%s" % (q, unit)]),
                               sig(t["delta_%s_significant" % q])]
            check(row == want_cells, "delta row %r == %r" % (row, want_cells))
    # Error bars: the trajectories' and deltas' u are drawn (data-u), as many bars as known u.
    drawn = [float(a["data-u"]) for tag, a in p.tags if tag == "line" and a.get("class") == "eb"]
    used = [pt for i, pt in enumerate(points) if i not in {e["record"] for e in analysis["points"]["excluded"]}]
    want_u = [c[k] for c in curves for k in ("mtpa_angle_u_deg", "me_angle_u_deg")]
    want_u += [d["mtpa"]["delta_im_u_A"] for d in des] + [d["me"]["delta_pdcm_u_W"] for d in des]
    want_u += [pt[k] for pt in used for k in ("im_u_A", "pdcm_u_W")]
    want_u = [u for u in want_u if u is not None]
    check(len(want_u) > 0 and sorted(round(u, 9) for u in drawn) == sorted(round(u, 9) for u in want_u),
          "one error bar per known u (trajectories, I_m/P_dcM points, deltas), its data-u the analysis' (%d drawn, %d known)"
          % (len(drawn), len(want_u)))
    check(page_text.count("bars: ±2u, 95 %") >= len({(c["estimator"], c["pwm"]) for c in curves}), "figures say what their bars are")
    # The uncertainty section: counts of significant differences as in the analysis JSON.
    st = [t for t in p.tables if t["id"] == "significance"]
    count = lambda vals: "%d of %d" % (sum(1 for v in vals if v), sum(1 for v in vals if v is not None))
    want_sig = [count([c["me_minus_mtpa_significant"] for c in curves]),
                count([d["mtpa"]["delta_angle_significant"] for d in des]), count([d["mtpa"]["delta_im_significant"] for d in des]),
                count([d["me"]["delta_angle_significant"] for d in des]), count([d["me"]["delta_pdcm_significant"] for d in des])]
    check(len(st) == 1 and [r[1] for r in st[0]["rows"][1:]] == want_sig,
          "the uncertainty section's counts of significant differences equal the analysis' (%r == %r)" %
          (st and [r[1] for r in st[0]["rows"][1:]], want_sig))
    check('id="uncertainty"' in page_text and "docs/uncertainty.md" in page_text and "No uncertainty stored" not in page_text,
          "the uncertainty section names docs/uncertainty.md")
    # The efficiency grids equal the efficiency map.
    grids = [t for t in p.tables if t["class"] == "eta-grid"]
    check(len(grids) == len(analysis["efficiency_map"]["entries"]), "one efficiency grid per configuration")
    for e in analysis["efficiency_map"]["entries"]:
        t = [t for t in grids if t["attrs"].get("data-estimator") == e["estimator"] and t["attrs"].get("data-pwm") == e["pwm"]]
        if not check(len(t) == 1, "grid of %s/%s" % (e["estimator"], e["pwm"])):
            continue
        got = t[0]["rows"]
        check(got[0][1:] == [g(l) for l in e["loads_Nm"]], "grid columns are the loads")
        for i, s in enumerate(e["speeds_rpm"]):
            check(got[i + 1] == [g(s)] + [fixed(v, 4) for v in e["efficiency"][i]], "grid row %s rpm" % s)
        tu = [t for t in p.tables if t["class"] == "eta-u-grid" and t["attrs"].get("data-estimator") == e["estimator"]
              and t["attrs"].get("data-pwm") == e["pwm"]]
        if check(len(tu) == 1, "a u grid of %s/%s" % (e["estimator"], e["pwm"])):
            for i, s in enumerate(e["speeds_rpm"]):
                check(tu[0]["rows"][i + 1] == [g(s)] + [u_text(v) for v in e["efficiency_u"][i]], "u grid row %s rpm" % s)
    excluded = analysis["points"]["excluded"]
    ex = [t for t in p.tables if t["id"] == "excluded"]
    check((len(ex[0]["rows"]) - 1 if ex else 0) == len(excluded), "exclusions listed (%d)" % len(excluded))
    check('"speed_rpm"' in page_text or "speed_rpm" in page_text, "the plan is in the page")

    # The CSV beside it: every stored point.
    records = list(csv.reader(io.StringIO(csv_text)))
    check(len(records) - 1 == sweep["points_stored"] == 2 * 2 * 3 * 7, "CSV rows %d == stored %d" %
          (len(records) - 1, sweep["points_stored"]))

    # A sweep from before the record had u: its points' u NULL, as the schema-8 migration leaves old rows.
    con = sqlite3.connect(db)
    con.execute("UPDATE points SET im_u_A = NULL, pdcm_u_W = NULL, pdcg_u_W = NULL, pm_u_W = NULL, efficiency_u = NULL, "
                "im_u_repeat_A = NULL, pdcm_u_repeat_W = NULL, efficiency_u_repeat = NULL WHERE sweep_id = 1")
    con.commit()
    con.close()
    r = subprocess.run([BIN, "report", "1", "--db", db, "--out", os.path.join(tmp, "old")], capture_output=True, text=True, timeout=120)
    old = open(r.stdout.split()[0], encoding="utf-8").read() if r.returncode == 0 else ""
    po = parse(old)
    opt_old = [t for t in po.tables if t["id"] == "optima"]
    check(r.returncode == 0 and "No uncertainty stored" in old and 'class="eb"' not in old and "bars: ±2u" not in old and
          opt_old and all(row[13:] == ["–"] * 5 + [row[18], "–", "–"] for row in opt_old[0]["rows"][1:]) and
          not [t for t in po.tables if t["id"] == "significance"],
          "a sweep without u: \"No uncertainty stored\", no error bars, no u, nothing significant")
    check.finish("report test ok")


main()
