#!/usr/bin/env python3
"""The documentation against the package: README.md and docs/*.md cannot name what is not there.

  - every relative link and image resolves (files, and #anchors to headings of .md pages);
  - every `roslaunch norm2tex X.launch arg:=v` shown names an existing launch file and args it has;
  - every `rosrun norm2tex T` names a program CMakeLists.txt installs;
  - every `norm2tex/XNodelet` named is exported in nodelet_plugins.xml;
  - every list of the recorder's manifest `stop_reason`s names exactly those the code writes (the
    constants of src/ros/dataset_recorder.hpp; src/ros writes no other string as one);
  - the parameter tables of docs/ros.md ("private parameter" tables under a node's heading) list
    exactly the private parameters the node's code reads (readParam / pnh.param / getParam in src/ros/), and
    the launch-argument tables ("launch arg" tables under a launch file's heading) exactly the
    arguments the launch file takes;
  - one home per headline figure: docs/performance.md's "headline figure" table names each
    (`key` | value | provenance); a page quotes one as
    `<!-- figure: key -->value<!-- /figure -->`, and every quote must name a key of that table
    and carry exactly its value (whitespace aside). performance.md itself quotes every key in
    the section that measured it, so the table cannot drift from its own measurements.

Usage: test_docs.py [PACKAGE_ROOT]   (default: two folders up). Stdlib only.
"""
import os
import re
import sys
import unittest
import xml.etree.ElementTree as ET

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else
                       os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))

# Which sources hold each node's parameter reads (the node's own reader and what it calls).
NODE_SOURCES = {
    "contact_sim": ["contact_sim.cpp"],
    "hand_sim": ["hand_sim_ros.cpp"],
    "tactile_renderer": ["tactile_renderer_ros.cpp"],
    "probe_sim": ["probe_sim.cpp"],
    "dataset_recorder": ["dataset_recorder.cpp", "nodelets.cpp"],
    "nodelet_group": ["nodelet_group_main.cpp"],
}
# Readers shared by several nodes: included where a node's source calls them.
# (Followed through: a shared reader may call another.)
SHARED_READERS = {"readLockStepParams": "lock_step.cpp", "readSimNodeParams": "sim_node_params.cpp"}


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def pages(root=ROOT):
    """README.md and docs/*.md, as (path, text)."""
    paths = [os.path.join(root, "README.md")]
    docs = os.path.join(root, "docs")
    if os.path.isdir(docs):
        paths += sorted(os.path.join(docs, f) for f in os.listdir(docs) if f.endswith(".md"))
    return [(p, read(p)) for p in paths if os.path.exists(p)]


# --- Markdown pieces -----------------------------------------------------------------------------
_FENCE = re.compile(r"^(```|~~~)")


def split_code(text):
    """(prose with code removed, list of code segments): fenced blocks' logical lines (a trailing
    backslash joins the next line) and inline code spans (newlines as spaces)."""
    prose, code, block, in_fence = [], [], [], False
    for line in text.split("\n"):
        if _FENCE.match(line.strip()):
            if in_fence:
                code += _logical_lines(block)
                block = []
            in_fence = not in_fence
            prose.append("")
            continue
        (block if in_fence else prose).append(line)
    if in_fence:
        code += _logical_lines(block)
    prose_text = "\n".join(prose)
    for span in re.findall(r"(`+)(.+?)\1", prose_text, flags=re.S):
        code.append(span[1].replace("\n", " "))
    prose_text = re.sub(r"(`+)(.+?)\1", " ", prose_text, flags=re.S)
    return prose_text, code


def fenced_blocks(text):
    """(info string, line number of the first code line, [code lines]) of every fenced block, in
    page order (the info string is the fence's language tag: "bash", "python", "" ...)."""
    blocks, block, info, start, in_fence = [], [], "", 0, False
    for number, line in enumerate(text.split("\n"), 1):
        m = _FENCE.match(line.strip())
        if m:
            if in_fence:
                blocks.append((info, start, block))
            else:
                info, start, block = line.strip()[3:].strip(), number + 1, []
            in_fence = not in_fence
            continue
        if in_fence:
            block.append(line)
    if in_fence:
        blocks.append((info, start, block))
    return blocks


def _logical_lines(lines):
    out, cur = [], ""
    for line in lines:
        if line.rstrip().endswith("\\"):
            cur += line.rstrip()[:-1] + " "
        else:
            out.append(cur + line)
            cur = ""
    if cur:
        out.append(cur)
    return out


def _strip_comment(line):
    return re.split(r"\s#\s", " " + line, maxsplit=1)[0]


def slug(heading):
    """GitHub's anchor for a heading's text."""
    text = re.sub(r"[`*_]{2,}|`", "", heading).strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(text):
    prose, _ = split_code_keep_headings(text)
    seen, out = {}, set()
    for line in prose.split("\n"):
        m = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if not m:
            continue
        base = slug(m.group(1))
        n = seen.get(base, 0)
        out.add(base if n == 0 else "%s-%d" % (base, n))
        seen[base] = n + 1
    return out


def split_code_keep_headings(text):
    """Text without fenced blocks (headings keep their inline code)."""
    lines, in_fence = [], False
    for line in text.split("\n"):
        if _FENCE.match(line.strip()):
            in_fence = not in_fence
            continue
        if not in_fence:
            lines.append(line)
    return "\n".join(lines), None


def links(text):
    """Targets of Markdown links and images and of HTML src/href, outside code."""
    prose, _ = split_code(text)
    out = re.findall(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)", prose)
    out += re.findall(r"\b(?:src|href)\s*=\s*\"([^\"]+)\"", prose)
    return out


def check_links(path, text, root=ROOT):
    errors = []
    for target in links(text):
        if re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", target):  # http:, mailto:, ...
            continue
        file_part, _, fragment = target.partition("#")
        resolved = path if not file_part else os.path.normpath(
            os.path.join(os.path.dirname(path), file_part))
        where = os.path.relpath(path, root)
        if not os.path.exists(resolved):
            errors.append("%s: link '%s' does not resolve" % (where, target))
            continue
        if fragment and resolved.endswith(".md"):
            if fragment not in anchors(read(resolved)):
                errors.append("%s: link '%s': no heading '#%s' in %s" %
                              (where, target, fragment, os.path.relpath(resolved, root)))
    return errors


# --- roslaunch, rosrun, nodelets ----------------------------------------------------------------
_ROSLAUNCH = re.compile(r"\broslaunch\s+(?:-\S+\s+(?:\S+\s+)?)*?norm2tex\s+([\w./-]+\.launch)\b(.*)")
_ROSRUN = re.compile(r"\brosrun\s+norm2tex\s+([\w./-]+)")


def roslaunch_uses(text):
    """(launch file, [arg names]) for every `roslaunch norm2tex X.launch a:=v ...` in code."""
    uses = []
    for segment in split_code(text)[1]:
        for line in segment.split("\n"):
            line = _strip_comment(line)
            for m in _ROSLAUNCH.finditer(line):
                rest = re.split(r"\s(?:&&|\|\||;|\|)\s|\broslaunch\b|\brosrun\b", m.group(2))[0]
                uses.append((m.group(1), re.findall(r"(?<![\w$(])([A-Za-z_]\w*):=", rest)))
    return uses


def rosrun_uses(text):
    out = []
    for segment in split_code(text)[1]:
        out += _ROSRUN.findall(_strip_comment(segment))
    return out


def launch_args(launch_path):
    """Arguments a user can set on a launch file: its top-level <arg>s without value=."""
    tree = ET.parse(launch_path)
    return {a.get("name") for a in tree.getroot().findall("arg") if a.get("value") is None}


def installed_programs(cmake_text):
    """What `rosrun norm2tex NAME` finds after `catkin_make install`."""
    text = re.sub(r"#.*", "", cmake_text)
    programs = set()
    lists = {}
    for m in re.finditer(r"\bset\s*\(\s*(\w+)\s+([^)]*)\)", text):
        lists[m.group(1)] = m.group(2).split()
    for m in re.finditer(r"\blist\s*\(\s*APPEND\s+(\w+)\s+([^)]*)\)", text):
        lists.setdefault(m.group(1), []).extend(m.group(2).split())
    for m in re.finditer(r"\binstall\s*\(\s*TARGETS\s+([^)]*)\)", text):
        body = m.group(1)
        if "CATKIN_PACKAGE_BIN_DESTINATION" not in body:
            continue
        for word in body.split("RUNTIME")[0].split():
            var = re.match(r"\$\{(\w+)\}", word)
            programs.update(lists.get(var.group(1), []) if var else [word])
    for m in re.finditer(r"\binstall\s*\(\s*PROGRAMS\s+([^)]*)\)", text):
        files, _, dest = m.group(1).partition("DESTINATION")
        sub = re.match(r"\s*\$\{CATKIN_PACKAGE_BIN_DESTINATION\}(?:/(\S+))?", dest)
        if not sub:
            continue
        for f in files.split():
            name = os.path.basename(f)
            programs.add(sub.group(1) + "/" + name if sub.group(1) else name)
    return programs


def exported_nodelets(plugins_xml):
    return {c.get("name") for c in ET.parse(plugins_xml).getroot().iter("class")}


# --- reference tables ---------------------------------------------------------------------------
def tables(text):
    """(heading, header cells, [rows of cells]) for every Markdown table outside code."""
    out, heading = [], ""
    lines = split_code_keep_headings(text)[0].split("\n")
    i = 0
    while i < len(lines):
        line = lines[i]
        if re.match(r"^#{1,6}\s", line):
            heading = line
        if line.lstrip().startswith("|") and i + 1 < len(lines) and \
                re.match(r"^\s*\|[\s:|-]+\|\s*$", lines[i + 1]):
            header = _cells(line)
            rows = []
            i += 2
            while i < len(lines) and lines[i].lstrip().startswith("|"):
                rows.append(_cells(lines[i]))
                i += 1
            out.append((heading, header, rows))
            continue
        i += 1
    return out


def _cells(line):
    line = line.strip().replace("\\|", "\x00")
    return [c.strip().replace("\x00", "|") for c in line.strip("|").split("|")]


def _ticked(cell):
    return re.findall(r"`([^`]+)`", cell)


def documented_params(text):
    """{node: set of parameter names} from "private parameter" tables under a node's heading."""
    out = {}
    for heading, header, rows in tables(text):
        if not header or header[0].lower() != "private parameter":
            continue
        names = _ticked(heading)
        node = names[0] if names else heading
        params = out.setdefault(node, set())
        for row in rows:
            params.update(t[1:] for t in _ticked(row[0]) if t.startswith("~"))
    return out


def documented_launch_args(text):
    """{launch file: set of args} from "launch arg" tables under a launch file's heading."""
    out = {}
    for heading, header, rows in tables(text):
        if not header or header[0].lower() != "launch arg":
            continue
        launch = next((t for t in _ticked(heading) if t.endswith(".launch")), heading)
        args = out.setdefault(launch, set())
        for row in rows:
            args.update(_ticked(row[0]))
    return out


_READ = re.compile(r"\b(?:pnh|private_nh_?|getPrivateNodeHandle\(\))\s*\.\s*"
                   r"(?:param|getParam|getParamCached|hasParam|searchParam)\b\s*"
                   r"(?:<[^;()]*>)?\s*\(\s*\"([^\"]+)\"")
# ros_params::readParam(pnh, "name", ...): the nodes' typed read (src/ros/params.hpp).
_TYPED_READ = re.compile(r"\breadParam\s*(?:<[^;()]*>)?\s*\(\s*"
                         r"(?:pnh|private_nh_?|getPrivateNodeHandle\(\))\s*,\s*\"([^\"]+)\"")


def params_read(source_text):
    code = re.sub(r"//.*", "", source_text)
    return set(_READ.findall(code)) | set(_TYPED_READ.findall(code))


def code_params(ros_dir):
    """{node: set of private parameters its code reads}, and the files with reads no node owns."""
    reads = {f: params_read(read(os.path.join(ros_dir, f)))
            for f in sorted(os.listdir(ros_dir)) if f.endswith(".cpp")}
    out = {}
    for node, files in NODE_SOURCES.items():
        params = set()
        sources, seen = list(files), set()
        while sources:
            f = sources.pop()
            if f in seen:
                continue
            seen.add(f)
            params |= reads.get(f, set())
            text = read(os.path.join(ros_dir, f))
            for reader, shared in SHARED_READERS.items():
                if re.search(r"\b%s\s*\(" % reader, text):
                    sources.append(shared)
        out[node] = params
    owned = {f for files in NODE_SOURCES.values() for f in files} | set(SHARED_READERS.values())
    unowned = sorted(f for f, names in reads.items() if names and f not in owned)
    return out, unowned


def compare(what, documented, actual):
    errors = []
    for name in sorted(documented - actual):
        errors.append("%s: '%s' is documented but not in the code" % (what, name))
    for name in sorted(actual - documented):
        errors.append("%s: '%s' is in the code but not documented" % (what, name))
    return errors


# --- the recorder's stop reasons ----------------------------------------------------------------
_STOP_LIST = re.compile(r"`stop_reason`\s*\(([^)]*)\)")
_STOP_LITERAL = re.compile(r'\bstop_reason_\s*=\s*"(\w*)"|\bclose\(\s*"(\w*)"')


def code_stop_reasons(ros_dir):
    """(the manifest's stop reasons: the constants of dataset_recorder.hpp's namespace
    stop_reason, [string literals written as a stop reason elsewhere in src/ros])."""
    header = read(os.path.join(ros_dir, "dataset_recorder.hpp"))
    block = re.search(r"namespace stop_reason \{(.*?)\n\}", header, re.S)
    reasons = set(re.findall(r'=\s*"(\w+)"', block.group(1))) if block else set()
    literals = []
    for f in sorted(os.listdir(ros_dir)):
        if f.endswith((".cpp", ".hpp")):
            text = re.sub(r"//.*", "", read(os.path.join(ros_dir, f)))
            literals += ["src/ros/%s: '%s'" % (f, a or b) for a, b in _STOP_LITERAL.findall(text)]
    return reasons, literals


def documented_stop_reasons(text):
    """Every list "`stop_reason` (`a`, `b`, ...)" of a page, as sets."""
    return [set(_ticked(m.group(1))) for m in _STOP_LIST.finditer(text)]


# --- headline figures: one home, quoted elsewhere -------------------------------------------
HOME_PAGE = os.path.join("docs", "performance.md")
_QUOTE = re.compile(r"<!--\s*figure:\s*([\w.-]*)\s*-->(.*?)<!--\s*/figure\s*-->", re.S)
_OPEN = re.compile(r"<!--\s*figure:")
_CLOSE = re.compile(r"<!--\s*/figure\s*-->")


def _norm(value):
    return " ".join(value.split())


def headline_figures(home_text):
    """({key: value} of the "headline figure" table, [problems]) of docs/performance.md."""
    figures, problems = {}, []
    for _, header, rows in tables(home_text):
        if not header or header[0].lower() != "headline figure":
            continue
        for row in rows:
            keys = _ticked(row[0])
            if len(keys) != 1 or len(row) < 2 or not row[1].strip():
                problems.append("headline figure row without one `key` and a value: %s" % row)
                continue
            if keys[0] in figures:
                problems.append("headline figure '%s' is in the table twice" % keys[0])
            figures[keys[0]] = _norm(row[1])
    return figures, problems


def figure_quotes(text):
    """([(key, quoted value)], [problems]) of a page's `<!-- figure: key -->value<!-- /figure -->`
    quotes (outside code); an opening marker without its closing one is a problem."""
    prose = split_code(text)[0]
    quotes = [(m.group(1), _norm(m.group(2))) for m in _QUOTE.finditer(prose)]
    problems = []
    rest = _QUOTE.sub("", prose)
    if _OPEN.search(rest) or _CLOSE.search(rest):
        problems.append("a figure marker without its pair (<!-- figure: key -->value"
                        "<!-- /figure -->, on one page, outside code)")
    for key, value in quotes:
        if _OPEN.search(value):
            problems.append("figure '%s': a quote inside a quote" % key)
    return quotes, problems


def check_figures(page_list, home_text, root=ROOT):
    """Every quote names a headline figure and equals it; the home page quotes each in its body."""
    figures, errors = headline_figures(home_text)
    if not figures:
        return errors + ["%s has no \"headline figure\" table" % HOME_PAGE]
    for path, text in page_list:
        where = os.path.relpath(path, root)
        quotes, problems = figure_quotes(text)
        errors += ["%s: %s" % (where, p) for p in problems]
        for key, value in quotes:
            if key not in figures:
                errors.append("%s: quotes figure '%s', which is not a headline figure of %s" %
                              (where, key, HOME_PAGE))
            elif value != figures[key]:
                errors.append("%s: quotes figure '%s' as '%s' where %s has '%s'" %
                              (where, key, value, HOME_PAGE, figures[key]))
    measured = {key for key, _ in figure_quotes(home_text)[0]}
    for key in sorted(set(figures) - measured):
        errors.append("%s: headline figure '%s' is not quoted in the section that measured it" %
                      (HOME_PAGE, key))
    return errors


# --- the checks over a package ------------------------------------------------------------------

# --- the package's programs and scripts on the pages: their options -----------------------------
# Options a program takes that its own source does not spell (Google Benchmark's flags).
_FOREIGN_OPTIONS = {"norm2tex_bench": re.compile(r"^benchmark_\w+$")}
_WRAPPERS = ("sudo", "time", "exec", "env", "nice", "timeout", "bash", "python3")


def program_sources(root, cmake_text):
    """{program: [source texts]}: scripts/* and every add_executable's .cpp files."""
    out = {}
    scripts = os.path.join(root, "scripts")
    for name in os.listdir(scripts):
        path = os.path.join(scripts, name)
        if os.path.isfile(path):
            out[name] = [read(path)]
    text = re.sub(r"#.*", "", cmake_text)
    for m in re.finditer(r"\badd_executable\s*\(\s*(\w+)\s+([^)]*)\)", text):
        files = [os.path.join(root, w) for w in m.group(2).split() if w.endswith(".cpp")]
        out[m.group(1)] = [read(f) for f in files if os.path.exists(f)]
    return out


def command_uses(text):
    """(program, [--options], how it was named) for every command of a code line: `scripts/X`,
    `rosrun norm2tex X`, or a bare `norm2tex_X`."""
    uses = []
    for segment in split_code(text)[1]:
        for line in segment.split("\n"):
            for part in re.split(r"\s(?:&&|\|\||;|\|)\s|\$\(|`", _strip_comment(line)):
                words = part.split()
                while words and (re.match(r"^\w+=\S*$", words[0]) or words[0] in _WRAPPERS or
                                 re.match(r"^-", words[0]) or re.match(r"^\d+[smh]?$", words[0])):
                    words = words[1:]
                if not words:
                    continue
                if words[0] == "rosrun" and len(words) > 2 and words[1] == "norm2tex":
                    program, rest, named = words[2], words[3:], "rosrun norm2tex " + words[2]
                elif re.match(r"^(\./|\S*/)?scripts/[\w/-]+$", words[0]):
                    program = re.sub(r"^(\./|\S*/)?scripts/", "", words[0])
                    rest, named = words[1:], "scripts/" + program
                elif re.match(r"^norm2tex_\w+$", words[0]):
                    program, rest, named = words[0], words[1:], words[0]
                else:
                    continue
                options = [m.group(1) for m in (re.match(r"^--([A-Za-z][\w-]*)", w) for w in rest)
                           if m and m.group(1) != "help"]
                uses.append((program, options, named))
    return uses


def check_commands(where, text, sources):
    """Errors for a page's commands: a program or script that is not there, an option its source
    does not declare (`--name` in a script, `"name"` in a program's option table)."""
    errors = []
    for program, options, named in command_uses(text):
        if program not in sources:
            if named.startswith("scripts/") and "/" not in program:
                errors.append("%s: %s: no such script" % (where, named))
            elif named.startswith("norm2tex_") and options:
                # (A bare name without options may be a library or node named in prose:
                # `norm2tex_core`, `norm2tex_manager`.)
                errors.append("%s: %s: no such program" % (where, named))
            continue
        foreign = _FOREIGN_OPTIONS.get(program)
        for option in options:
            if foreign and foreign.match(option):
                continue
            spelled = ("--" + option, '"%s"' % option, '"%s,' % option)
            if not any(any(s in src for s in spelled) for src in sources[program]):
                errors.append("%s: %s --%s: not an option of %s" % (where, named, option, program))
    return errors


def check_package(root=ROOT, page_list=None):
    """Every problem found, as one-line messages."""
    page_list = pages(root) if page_list is None else page_list
    errors = []
    cmake_text = read(os.path.join(root, "CMakeLists.txt"))
    programs = installed_programs(cmake_text)
    sources = program_sources(root, cmake_text)
    nodelets = exported_nodelets(os.path.join(root, "nodelet_plugins.xml"))
    for path, text in page_list:
        where = os.path.relpath(path, root)
        errors += check_links(path, text, root)
        errors += check_commands(where, text, sources)
        for launch, args in roslaunch_uses(text):
            launch_path = os.path.join(root, "launch", launch)
            if not os.path.exists(launch_path):
                errors.append("%s: roslaunch norm2tex %s: no such launch file" % (where, launch))
                continue
            for arg in sorted(set(args) - launch_args(launch_path)):
                errors.append("%s: roslaunch norm2tex %s: no arg '%s'" % (where, launch, arg))
        for program in rosrun_uses(text):
            if program not in programs:
                errors.append("%s: rosrun norm2tex %s: not installed by CMakeLists.txt" %
                              (where, program))
        for nodelet in re.findall(r"\bnorm2tex/\w+Nodelet\b", text):
            if nodelet not in nodelets:
                errors.append("%s: %s is not exported in nodelet_plugins.xml" % (where, nodelet))
        for launch, args in documented_launch_args(text).items():
            launch_path = os.path.join(root, "launch", launch)
            if not os.path.exists(launch_path):
                errors.append("%s: table of %s: no such launch file" % (where, launch))
                continue
            errors += compare("%s: %s args" % (where, launch), args, launch_args(launch_path))
        for listed in documented_stop_reasons(text):
            reasons, _ = code_stop_reasons(os.path.join(root, "src", "ros"))
            errors += compare("%s: stop reasons" % where, listed, reasons)
        documented = documented_params(text)
        if documented:
            actual, unowned = code_params(os.path.join(root, "src", "ros"))
            for node, params in documented.items():
                if node not in actual:
                    errors.append("%s: parameter table of '%s': no such node" % (where, node))
                    continue
                errors += compare("%s: %s parameters" % (where, node), params, actual[node])
            for node in sorted(set(actual) - set(documented)):
                errors.append("%s: node '%s' has no parameter table" % (where, node))
            for f in unowned:
                errors.append("src/ros/%s reads private parameters of a node the docs check "
                              "does not know (add it to NODE_SOURCES)" % f)
    home = os.path.join(root, HOME_PAGE)
    if os.path.exists(home):
        errors += check_figures(page_list, read(home), root)
    return errors


class DocsTest(unittest.TestCase):
    """The shipped README.md and docs/ against the package."""

    def test_pages_exist(self):
        names = [os.path.relpath(p, ROOT) for p, _ in pages()]
        self.assertIn("README.md", names)
        self.assertIn(os.path.join("docs", "ros.md"), names)

    def test_docs_match_the_package(self):
        errors = check_package()
        self.assertEqual(errors, [], "\n" + "\n".join(errors))

    def test_scripts_help_says_whole_sentences(self):
        # argparse's description from a docstring's first *line* cut `--help` mid-sentence
        # ("reports its accuracy on"): a script takes its first paragraph, which ends a sentence.
        scripts = os.path.join(ROOT, "scripts")
        for name in sorted(os.listdir(scripts)):
            path = os.path.join(scripts, name)
            if not os.path.isfile(path):
                continue
            text = read(path)
            if not text.startswith("#!/usr/bin/env python3") or "description=__doc__" not in text:
                continue
            self.assertFalse("__doc__.splitlines()[0]" in text,
                             name + ": --help's description is the docstring's first line; use its first paragraph")
            doc = re.search(r'^"""(.*?)"""', text.split("\n", 1)[1], re.S)
            self.assertIsNotNone(doc, name)
            first = doc.group(1).split("\n\n")[0].strip()
            self.assertTrue(first.endswith("."), "%s: --help's description %r" % (name, first))

    def test_stop_reasons_are_listed_and_only_the_constants_are_written(self):
        reasons, literals = code_stop_reasons(os.path.join(ROOT, "src", "ros"))
        self.assertIn("last_frame", reasons)
        self.assertEqual(literals, [], "write stop reasons through the stop_reason constants")
        datasets_md = read(os.path.join(ROOT, "docs", "datasets.md"))
        self.assertEqual(documented_stop_reasons(datasets_md), [reasons])

    def test_ros_md_has_every_node_table(self):
        ros_md = read(os.path.join(ROOT, "docs", "ros.md"))
        self.assertEqual(set(documented_params(ros_md)), set(NODE_SOURCES))
        self.assertEqual(set(documented_launch_args(ros_md)),
                         {"gripper_sim.launch", "hand_sim.launch", "record_dataset.launch"})


class CheckerCatchesBrokenPages(unittest.TestCase):
    """The check itself: a page naming something that is not there fails it."""

    def broken(self, text):
        path = os.path.join(ROOT, "docs", "broken_example.md")
        return check_package(ROOT, [(path, text)])

    def test_good_page_passes(self):
        self.assertEqual(self.broken(
            "See [ros](ros.md#frames) and ![x](images/rviz.png).\n\n"
            "```bash\nroslaunch norm2tex gripper_sim.launch mode:=synchronous  # ok:=no\n"
            "rosrun norm2tex norm2tex_bake in.png -o out.tiff\n"
            "rosrun norm2tex slurm/submit_dataset 2 /tmp/x\n```\n"), [])

    def test_missing_file_link_and_image(self):
        errors = self.broken("[a](nowhere.md) ![b](images/missing.png)\n")
        self.assertEqual(len(errors), 2, errors)

    def test_missing_anchor(self):
        self.assertEqual(len(self.broken("[a](ros.md#no-such-heading)\n")), 1)

    def test_links_in_code_are_not_links(self):
        self.assertEqual(self.broken("`[a](nowhere.md)`\n"), [])

    def test_roslaunch_missing_file_and_arg(self):
        errors = self.broken("```bash\nroslaunch norm2tex nope.launch\n"
                             "roslaunch norm2tex gripper_sim.launch mode:=synchronous colour:=red\n```\n"
                             "Inline: `roslaunch norm2tex record_dataset.launch out:=/x sample:=3`.\n")
        self.assertEqual(len(errors), 3, errors)
        self.assertTrue(any("'colour'" in e for e in errors))
        self.assertTrue(any("'sample'" in e for e in errors))

    def test_rosrun_not_installed(self):
        errors = self.broken("```bash\nrosrun norm2tex quickstart run\n"
                             "rosrun norm2tex norm2tex_frobnicate\n```\n")
        self.assertEqual(len(errors), 2, errors)

    def test_programs_scripts_and_their_options(self):
        errors = self.broken("```bash\nscripts/record_dataset /tmp/x material:=wood\n"
                             "scripts/texture_contrast --forces 2,5 --figure x.png\n"
                             "scripts/record_datasets /tmp/x\n"
                             "norm2tex_render --mesh box:30x30x30 --colour red\n"
                             "rosrun norm2tex norm2tex_bake in.png -o out.tiff --speed fast\n"
                             "norm2tex_bench --benchmark_filter=Render\nnorm2tex_frobnicate --all\n```\n")
        self.assertEqual(len(errors), 4, errors)
        self.assertTrue(any("scripts/record_datasets: no such script" in e for e in errors))
        self.assertTrue(any("--colour: not an option of norm2tex_render" in e for e in errors))
        self.assertTrue(any("--speed: not an option of norm2tex_bake" in e for e in errors))
        self.assertTrue(any("norm2tex_frobnicate: no such program" in e for e in errors))

    def test_unknown_nodelet(self):
        self.assertEqual(len(self.broken("`norm2tex/FooNodelet`\n")), 1)

    def test_param_table_drift(self):
        page = ("## `contact_sim` (node)\n\n| private parameter | default | meaning |\n|---|---|---|\n"
                "| `~mode` | real_time | |\n| `~colour` | red | |\n")
        errors = [e for e in self.broken(page) if "contact_sim parameters" in e]
        self.assertTrue(any("'colour' is documented but not in the code" in e for e in errors))
        self.assertTrue(any("'scene' is in the code but not documented" in e for e in errors))

    def test_launch_table_drift(self):
        page = ("## `gripper_sim.launch`\n\n| launch arg | default | meaning |\n|---|---|---|\n"
                "| `mode` | real_time | |\n| `colour` | red | |\n")
        errors = self.broken(page)
        self.assertTrue(any("'colour' is documented but not in the code" in e for e in errors))
        self.assertTrue(any("'material' is in the code but not documented" in e for e in errors))

    def test_stop_reason_drift(self):
        errors = self.broken("the manifest's `stop_reason` (`last_frame`, `sample_target`, "
                             "`signal`, `error`, `disk_full`)\n")
        self.assertTrue(any("'signal' is documented but not in the code" in e for e in errors))
        self.assertTrue(any("'shutdown' is in the code but not documented" in e for e in errors))

    def test_figure_drift(self):
        home = read(os.path.join(ROOT, HOME_PAGE))
        figures, _ = headline_figures(home)
        self.assertIn("render_held_cube", figures)
        right = "<!-- figure: render_held_cube -->%s<!-- /figure -->" % figures["render_held_cube"]
        self.assertEqual(self.broken("A frame: **%s**.\n" % right), [])
        self.assertEqual(self.broken("| a | %s |\n" % right.replace(" ms", "\n ms")), [])
        drifted = "A frame: <!-- figure: render_held_cube -->1.42–1.49 ms<!-- /figure -->.\n"
        errors = self.broken(drifted)
        self.assertEqual(len(errors), 1, errors)
        self.assertIn("quotes figure 'render_held_cube' as '1.42–1.49 ms'", errors[0])
        self.assertEqual(len(self.broken("<!-- figure: no_such_key -->1 ms<!-- /figure -->\n")), 1)
        self.assertEqual(len(self.broken("<!-- figure: render_held_cube -->1.45 ms\n")), 1)
        self.assertEqual(self.broken("```\n<!-- figure: x -->1 ms\n```\n"), [])

    def test_home_table_drift(self):
        home = ("| headline figure | value | from |\n|---|---|---|\n"
                "| `a` | 1 ms | here |\n| `b` | 2 ms | here |\n\n"
                "measured: <!-- figure: a -->1 ms<!-- /figure -->, "
                "<!-- figure: b -->3 ms<!-- /figure -->\n")
        path = os.path.join(ROOT, HOME_PAGE)
        errors = check_figures([(path, home)], home)
        self.assertEqual(len(errors), 1, errors)
        self.assertIn("'b' as '3 ms'", errors[0])
        self.assertEqual(len(check_figures([], "| headline figure | value |\n|---|---|\n"
                                           "| `a` | 1 ms |\n")), 1)  # not measured in the body

    def test_code_reads_are_found(self):
        src = ('pnh.param<std::string>("a", x, "d");\n  pnh.param("b", y, 1);\n'
               'if (!pnh.getParam("c", z)) {}\n getPrivateNodeHandle().param("d", w, true);\n'
               '// pnh.param("commented", q, 0);\n nh_.param("global", g, 0);\n'
               'readParam<std::string>(pnh, "e", v, "");\n'
               'ros_params::readParam(getPrivateNodeHandle(), "f", b, true);\n'
               '// readParam(pnh, "commented", q, 0);\n readParam(nh_, "global", g, 0);\n')
        self.assertEqual(params_read(src), {"a", "b", "c", "d", "e", "f"})


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
