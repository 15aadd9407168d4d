#!/usr/bin/env python3
"""Checks a tool's --summary JSON against the tool's other output (issue 20).

  check_summary.py lobes   SUMMARY.json LOBES.csv
  check_summary.py map     SUMMARY.json POINTS.csv
  check_summary.py frf     SUMMARY.json FRF.csv
  check_summary.py tracker SUMMARY.json TRACKER.csv

Every summary must carry robomach_version. The values compared are written
by both outputs from the same doubles in shortest round-trip form, so they
must be equal exactly, except where noted.
"""
import csv
import json
import math
import sys


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def metadata(path):
    meta = {}
    with open(path) as f:
        for line in f:
            if line.startswith("# ") and ":" in line:
                k, v = line[2:].split(":", 1)
                meta[k.strip()] = v.strip()
    return meta


failures = []


def expect(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


def main():
    kind, summary_path, other_path = sys.argv[1:4]
    s = json.load(open(summary_path))
    expect(isinstance(s.get("robomach_version"), str) and s["robomach_version"], "robomach_version present")
    r = rows(other_path)
    if kind == "lobes":
        expect(len(s["lobes"]) > 0, "at least one lobe entry")
        total = 0
        for e in s["lobes"]:
            mine = [x for x in r if x["pose_id"] == e["pose_id"] and x["method"] == e["method"]]
            total += len(mine)
            expect(len(mine) == e["speeds"], f"{e['pose_id']} {e['method']}: speeds {e['speeds']} == {len(mine)} CSV rows")
            depths = [float(x["critical_depth_mm"]) for x in mine if x["critical_depth_mm"]]
            expect(len(depths) == e["speeds_with_boundary"], f"speeds_with_boundary {e['speeds_with_boundary']} == {len(depths)}")
            lo = min(depths)
            hi = max(depths)
            expect(e["min_critical_depth_mm"] == lo, f"min_critical_depth_mm {e['min_critical_depth_mm']} == CSV min {lo}")
            expect(e["max_critical_depth_mm"] == hi, f"max_critical_depth_mm {e['max_critical_depth_mm']} == CSV max {hi}")
            at = [float(x["spindle_speed_rpm"]) for x in mine if x["critical_depth_mm"] and float(x["critical_depth_mm"]) == lo]
            expect(e["min_critical_depth_speed_rpm"] in at, f"speed at the min {e['min_critical_depth_speed_rpm']} in {at}")
        expect(total == len(r), f"every CSV row counted ({total} of {len(r)})")
        # Issue #34 item 6: the numbers told on stderr are in the summary.
        for t in s.get("tips", []):
            pid = t["pose_id"]
            c = t.get("zoa_sd_comparison")
            if c is not None:
                zoa = [float(x["critical_depth_mm"]) for x in r
                       if x["pose_id"] == pid and x["method"] == "zoa" and x["critical_depth_mm"]]
                sd = [float(x["critical_depth_mm"]) for x in r
                      if x["pose_id"] == pid and x["method"] == "sd" and x["critical_depth_mm"]]
                expect(c["zoa_min_critical_depth_mm"] == min(zoa), f"{pid}: comparison's ZOA min == CSV ZOA min")
                # The SD's minimum also searches speeds near the ZOA's lobe
                # bottoms that are in no CSV row: at most the CSV's.
                expect(c["sd_min_critical_depth_mm"] <= min(sd), f"{pid}: comparison's SD min <= CSV SD min")
                a, b = c["sd_min_critical_depth_mm"], c["zoa_min_critical_depth_mm"]
                expect(math.isclose(c["difference_percent"], 100 * abs(a - b) / min(a, b), rel_tol=1e-9),
                       f"{pid}: difference_percent {c['difference_percent']}")
                expect(c["agree"] == (c["difference_percent"] <= 10.0), f"{pid}: agree")
            labels = {f["frf"]: f for f in t.get("fits", [])}
            for f in t.get("fits", []):
                if "same_as" in f:
                    expect(f["same_as"] in labels and labels[f["same_as"]]["modes"] == f["modes"],
                           f"{f['frf']}: the modes of {f['same_as']}, whose fit it reuses")
    elif kind == "map":
        expect(s["points"] == len(r), f"points {s['points']} == {len(r)} CSV rows")
        depths = [float(x["critical_depth_mm"]) for x in r if x["critical_depth_mm"]]
        expect(s["points_with_critical_depth"] == len(depths), f"points_with_critical_depth == {len(depths)}")
        expect(s["min_critical_depth_mm"] == min(depths), f"min_critical_depth_mm {s['min_critical_depth_mm']} == CSV min {min(depths)}")
        expect(s["max_critical_depth_mm"] == max(depths), f"max_critical_depth_mm {s['max_critical_depth_mm']} == CSV max {max(depths)}")
        p = s["min_critical_depth_point"]
        row = [x for x in r if int(x["row"]) == p["row"] and int(x["col"]) == p["col"]][0]
        expect(float(row["critical_depth_mm"]) == p["critical_depth_mm"] and row["status"] == p["status"],
               "the min point's CSV row has that depth and status")
        statuses = {}
        for x in r:
            statuses[x["status"]] = statuses.get(x["status"], 0) + 1
        expect(statuses == s["points_by_status"], f"points_by_status {s['points_by_status']} == CSV {statuses}")
    elif kind == "frf":
        expect(s["frf_count"] == len(s["frfs"]), "frf_count == entries")
        total = 0
        for e in s["frfs"]:
            mine = [x for x in r if x["pose_id"] == e["pose_id"] and x["response"] == e["response"]
                    and x["excitation"] == e["excitation"]]
            total += len(mine)
            expect(len(mine) == e["lines"], f"{e['pose_id']} H{e['response']}{e['excitation']}: lines {e['lines']} == {len(mine)}")
            mags = [abs(complex(float(x["re"]), float(x["im"]))) for x in mine]
            k = max(range(len(mags)), key=lambda i: mags[i])
            expect(float(mine[k]["freq_hz"]) == e["peak_freq_hz"], f"peak_freq_hz {e['peak_freq_hz']} == CSV {mine[k]['freq_hz']}")
            # |re + i im| from the two printed parts: the same double up to the
            # rounding of one hypot, 1e-15 relative; 1e-12 leaves room.
            expect(math.isclose(mags[k], e["peak_receptance_m_per_N"], rel_tol=1e-12),
                   f"peak_receptance_m_per_N {e['peak_receptance_m_per_N']} ~ {mags[k]}")
            expect(float(mine[0]["freq_hz"]) == e["freq_min_hz"] and float(mine[-1]["freq_hz"]) == e["freq_max_hz"],
                   "band ends")
        expect(total == len(r), f"every CSV row counted ({total} of {len(r)})")
    elif kind == "tracker":
        expect(s["load_cases"] == len(r), f"load_cases {s['load_cases']} == {len(r)} CSV rows")
        meta = metadata(other_path)
        for j, k in enumerate(s["truth_kq_Nm_per_rad"]):
            key = f"truth_kq{j + 1}_Nm_per_rad"
            expect(float(meta[key]) == k, f"{key}: {k} == CSV metadata {meta[key]}")
        expect(sorted(s["outlier_cases"]) == sorted(meta.get("outlier_cases", "").split()), "outlier_cases")
        d = [math.dist([float(x[c + "1_mm"]) for c in "xyz"], [float(x[c + "0_mm"]) for c in "xyz"]) for x in r]
        # The JSON takes |p1 - p0| in metres, the CSV prints each coordinate
        # (about 1e3 mm) in round-trip form: differences of ~0.1 mm keep about
        # 1e-12 relative; 1e-9 leaves room.
        expect(math.isclose(max(d), s["deflection_max_mm"], rel_tol=1e-9), f"deflection_max_mm {s['deflection_max_mm']} ~ {max(d)}")
        expect(math.isclose(min(d), s["deflection_min_mm"], rel_tol=1e-9), f"deflection_min_mm {s['deflection_min_mm']} ~ {min(d)}")
    else:
        sys.exit("unknown kind " + kind)
    if failures:
        sys.exit(f"{len(failures)} check(s) failed")


main()
