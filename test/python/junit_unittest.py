#!/usr/bin/env python3
"""Runs a unittest file and writes a JUnit XML result, for catkin_run_tests_target.

Usage: junit_unittest.py TEST_FILE RESULT_XML [ARGS passed to the test as sys.argv[1:]]
Stdlib only. Exit status 0 when every test passed.
"""
import importlib.util
import sys
import time
import unittest
import xml.etree.ElementTree as ET


class _Recorder(unittest.TextTestResult):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.cases = []  # (name, seconds, kind, text)
        self._start = 0.0

    def startTest(self, test):
        self._start = time.time()
        super().startTest(test)

    def _add(self, test, kind, text=""):
        self.cases.append((test.id(), time.time() - self._start, kind, text))

    def addSuccess(self, test):
        super().addSuccess(test)
        self._add(test, "pass")

    def addFailure(self, test, err):
        super().addFailure(test, err)
        self._add(test, "failure", self._exc_info_to_string(err, test))

    def addError(self, test, err):
        super().addError(test, err)
        self._add(test, "error", self._exc_info_to_string(err, test))

    def addSkip(self, test, reason):
        super().addSkip(test, reason)
        self._add(test, "skipped", reason)


def main():
    test_file, result_xml = sys.argv[1], sys.argv[2]
    sys.argv = [test_file] + sys.argv[3:]
    spec = importlib.util.spec_from_file_location("norm2tex_python_test", test_file)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    suite = unittest.defaultTestLoader.loadTestsFromModule(module)
    runner = unittest.TextTestRunner(resultclass=_Recorder, verbosity=2)
    result = runner.run(suite)
    root = ET.Element("testsuite", name=module.__name__, tests=str(len(result.cases)),
                      failures=str(len(result.failures)), errors=str(len(result.errors)),
                      skipped=str(len(result.skipped)))
    for name, seconds, kind, text in result.cases:
        case = ET.SubElement(root, "testcase", classname=name.rsplit(".", 1)[0],
                             name=name.rsplit(".", 1)[-1], time=f"{seconds:.3f}")
        if kind != "pass":
            ET.SubElement(case, kind, message=text.splitlines()[-1] if text else kind).text = text
    ET.ElementTree(root).write(result_xml, encoding="utf-8", xml_declaration=True)
    sys.exit(0 if result.wasSuccessful() else 1)


if __name__ == "__main__":
    main()
