#!/usr/bin/python3
"""Summarise catkin test results: print every failed case and end with 'N passed, N failed'.

Counts each gtest case (gtest-*.xml) and each case of the gtest nodes that rostests run
(rosunit-*.xml). A rostest whose node never reported (crash, timeout, missing binary) leaves
only its rostest-*.xml or a catkin 'MISSING-' result: that counts as one failed case.
Exit status is 1 when anything failed or nothing ran.
"""
import glob
import os
import sys
import xml.etree.ElementTree as ET


def cases(path):
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as err:
        yield (os.path.basename(path), "unreadable result file: %s" % err, False)
        return
    for case in root.iter("testcase"):
        name = "%s.%s" % (case.get("classname", ""), case.get("name", ""))
        problems = case.findall("failure") + case.findall("error")
        if case.get("status") == "notrun" or case.find("skipped") is not None:
            yield (name, None, True)
            continue
        message = "\n".join((p.get("message") or "") + "\n" + (p.text or "") for p in problems)
        yield (name, message.strip() if problems else None, False)


def main():
    results_dir = sys.argv[1] if len(sys.argv) > 1 else "test_results"
    files = sorted(glob.glob(os.path.join(results_dir, "**", "*.xml"), recursive=True))
    passed, failed, skipped = 0, [], 0
    rosunit_tests = {os.path.basename(f)[len("rosunit-"):-4] for f in files
                     if os.path.basename(f).startswith("rosunit-")}
    for path in files:
        base = os.path.basename(path)
        if base.startswith("rostest-"):
            # One case per <test> of the launch file, named "test" + test-name. Its gtest node's
            # own cases are counted from rosunit-<test-name>.xml; a node that never reported
            # (crash, time limit, missing binary) has no such file and counts here as failed.
            for name, message, _ in cases(path):
                test_name = name.rsplit(".", 1)[-1]
                test_name = test_name[4:] if test_name.startswith("test") else test_name
                if test_name in rosunit_tests and not message:
                    continue
                failed.append((base + ": " + name, message or "rostest node produced no result"))
            continue
        for name, message, was_skipped in cases(path):
            if was_skipped:
                skipped += 1
            elif message:
                failed.append((base + ": " + name, message))
            else:
                passed += 1
    for name, message in failed:
        print("FAILED %s\n    %s" % (name, message.replace("\n", "\n    ")))
    if passed + len(failed) == 0:
        print("no test results found in %s" % results_dir)
    line = "%d passed, %d failed" % (passed, len(failed))
    if skipped:
        line += ", %d skipped" % skipped
    print(line)
    return 1 if failed or passed == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
