#!/usr/bin/env python3
"""Summarise the JUnit XML files that `catkin_make run_tests` leaves behind.

Usage: junit_summary.py RESULTS_DIR [--runner-rc N]

Why not `catkin_test_results`: it counts from the <testsuite> attributes, which
some writers leave wrong, prints nothing usable when no XML exists and has no
notion of "zero tests ran". We count <testcase> elements ourselves (stdlib only,
so it runs on the bare system python):

  * failed  -- the testcase has a <failure> or <error> child. This includes the
               synthetic MISSING-*.xml catkin writes when a test binary crashed
               or produced no result file.
  * skipped -- it has a <skipped> child, or gtest marked it status="notrun"
               (DISABLED_ tests), i.e. it never executed.
  * passed  -- everything else.

An XML file that cannot be parsed counts as one failure (a truncated result is
a broken test, not a pass). A suite that declares failures/errors but contains
no <testcase> also counts as one failure. --runner-rc is the exit status of
`catkin_make run_tests`: catkin's run_tests targets ignore test exit codes, so a
non-zero status means a test target failed to build or the runner itself broke,
which counts as one failure too.

Output: one line per failing testcase (file, test, first line of the message),
then exactly one final line `N passed, N failed[, N skipped]`.
Exit status: 0 only if nothing failed and at least one test executed.
"""

import argparse
import os
import re
import sys
import xml.etree.ElementTree as ET

MAX_MSG = 300  # keep per-failure lines readable in CI logs
LOCATION_ONLY = re.compile(r"^\S+:\d+$")


def first_line(text):
    lines = [l.strip() for l in (text or "").splitlines() if l.strip()]
    if not lines:
        return ""
    line = lines[0]
    # For a Python traceback the exception is on the last line.
    if line.startswith("Traceback (most recent call last)"):
        line = lines[-1]
    # gtest puts only "file:line" on the first line; the assertion follows.
    if len(lines) > 1 and LOCATION_ONLY.match(line):
        line = "%s: %s" % (line, lines[1])
    return line if len(line) <= MAX_MSG else line[:MAX_MSG] + "..."


def failure_message(elem):
    """First non-empty line of a <failure>/<error>: message attribute, else body."""
    return (first_line(elem.get("message")) or first_line(elem.text)
            or "(%s without message)" % elem.tag)


def int_attr(elem, name):
    try:
        return int(elem.get(name, "0"))
    except ValueError:
        return 0


def xml_files(results_dir):
    # Same walk as catkin_test_results: every *.xml, skipping dot-directories.
    for dirpath, dirnames, filenames in os.walk(results_dir):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith("."))
        for name in sorted(filenames):
            if name.endswith(".xml"):
                yield os.path.join(dirpath, name)


def summarise_file(path, rel, out):
    """Return (passed, failed, skipped) for one file (None if not JUnit);
    failure lines are appended to `out`."""
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError) as exc:
        out.append("FAILED %s: unreadable result XML (%s)" % (rel, first_line(str(exc))))
        return 0, 1, 0
    if root.tag not in ("testsuite", "testsuites"):
        print("note: %s: not JUnit XML (root <%s>), ignored" % (rel, root.tag))
        return None

    passed = failed = skipped = 0
    cases = list(root.iter("testcase"))
    for case in cases:
        name = case.get("name", "?")
        cls = case.get("classname")
        label = "%s.%s" % (cls, name) if cls else name
        bad = case.find("failure")
        if bad is None:
            bad = case.find("error")
        if bad is not None:
            failed += 1
            out.append("FAILED %s: %s: %s" % (rel, label, failure_message(bad)))
        elif case.find("skipped") is not None or case.get("status") == "notrun":
            skipped += 1
        else:
            passed += 1

    if not cases:
        suites = [root] if root.tag == "testsuite" else [root] + list(root.iter("testsuite"))
        declared = sum(int_attr(s, "failures") + int_attr(s, "errors") for s in suites)
        if declared:
            failed += 1
            out.append("FAILED %s: suite reports %d failure(s)/error(s) but lists no testcase"
                       % (rel, declared))
        else:
            print("note: %s: contains no testcase" % rel)
    return passed, failed, skipped


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("results_dir")
    ap.add_argument("--runner-rc", type=int, default=0,
                    help="exit status of `catkin_make run_tests` (non-zero = one failure)")
    args = ap.parse_args(argv)

    results_dir = os.path.abspath(args.results_dir)
    total_p = total_f = total_s = 0
    failures = []
    nfiles = 0
    if os.path.isdir(results_dir):
        for path in xml_files(results_dir):
            nfiles += 1
            rel = os.path.relpath(path, results_dir)
            counts = summarise_file(path, rel, failures)
            if counts is None:
                continue
            p, f, s = counts
            # Deliberately not "N passed, N failed": only the last line may look so.
            print("%-4s %s (pass=%d fail=%d skip=%d)"
                  % ("ok" if f == 0 else "FAIL", rel, p, f, s))
            total_p, total_f, total_s = total_p + p, total_f + f, total_s + s

    if args.runner_rc != 0:
        total_f += 1
        failures.append("FAILED catkin_make run_tests: exited with status %d "
                        "(a test target failed to build or the test runner broke; "
                        "see the log above)" % args.runner_rc)

    for line in failures:
        print(line)

    ok = True
    if total_f:
        ok = False
    if total_p + total_f == 0:
        ok = False
        if nfiles == 0:
            why = "no JUnit XML found under %s" % results_dir
        else:
            why = "%d result file(s) under %s hold no executed testcase" % (nfiles, results_dir)
        print("ERROR: no tests ran: %s (are tests registered with catkin_add_gtest/"
              "add_rostest and CATKIN_ENABLE_TESTING on?)" % why)

    summary = "%d passed, %d failed" % (total_p, total_f)
    if total_s:
        summary += ", %d skipped" % total_s
    print(summary)
    sys.stdout.flush()
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
