#!/usr/bin/env python3
"""The one-click report (docs/report.md) against the real `synbench sweep`, `synbench report` and
`synbench serve`: a two-configuration sweep into a temporary database; the report's HTML is
self-contained (no script, no external src/href), has one inline SVG per figure the analysis
has data for, each titled with the sweep and its configuration; its MTPA/ME table and efficiency
grids equal the daemon's analysis JSON to the printed precision; the CSV beside it has every
stored point; the daemon's GET /api/sweeps/{id}/report and report.csv give the same bytes as the
command line (modulo the generation time); clear errors for an unknown sweep, no database, a bad
id. Standard library only.

usage: report_test.py path/to/synbench
"""
import csv
import html.parser
import io
import os
import re
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
    excluded = analysis["points"]["excluded"]
    ex = [t for t in p.tables if t["id"] == "excluded"]
    check((len(ex[0]["rows"]) - 1 if ex else 0) == len(excluded), "exclusions listed (%d)" % len(excluded))
    check('"speed_rpm"' in page_text or "speed_rpm" in page_text, "the plan is in the page")

    # The CSV beside it: every stored point.
    records = list(csv.reader(io.StringIO(csv_text)))
    check(len(records) - 1 == sweep["points_stored"] == 2 * 2 * 3 * 7, "CSV rows %d == stored %d" %
          (len(records) - 1, sweep["points_stored"]))
    check.finish("report test ok")


main()
