#!/usr/bin/env python3
"""Runs the examples of one Markdown document, so that no document can go stale.

    doc_examples.py DOC.md --zcheck EXE --python-path DIR --models DIR --source DIR

Every fenced block of DOC.md is an example of one kind, named by its info string:

  console   `$ command` lines (a line ending in a backslash continues it), each followed by
            the output it must print: stdout then stderr, compared line by line after
            trailing spaces are stripped. In the expected output a line `[...]` stands for
            any number of lines, a line ending in ` [...]` for any line beginning with what
            comes before it, and a last line `[exit N]` for the exit status (default 0). A
            command followed by no output must only exit as stated.
  sh        a bash script (set -euo pipefail) that must exit 0.
  python    a script run with the build's Python module; when the next block is an
            `output` block, its stdout must be that block (same rules as console).
  json      must parse as JSON; preceded by `<!-- file: NAME -->` it is also written to NAME
            in the working folder, for the examples after it.

A block may be indented (in a list item): its fence's indentation is taken off its lines.
  cpp, cmake  preceded by `<!-- from: PATH -->`: every line of the block must appear, in
            order, in PATH (relative to the source tree), a file another test builds.
  text, output, and blocks without an info string are not examples (synopses, diagrams).

The blocks of a document run in order in one fresh folder holding `examples/` (the
repository's) and `models/` (the shared meshes), with `zcheck` first on PATH. A failure
prints the block's line number, the command, and the difference; the exit status is 1.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

FENCE = re.compile(r"^( *)```(\S*)\s*$")
DIRECTIVE = re.compile(r"^\s*<!--\s*(file|from):\s*(\S+)\s*-->\s*$")
# One example's limit: docs/suite.md's whole suite (the linear matrix and the lens part, ~1.5 min
# on 2 idle cores) must finish under the sanitizers, ~3x slower, beside other tests.
TIMEOUT_SECONDS = 900


def blocks(path):
    """(info, first line number, lines, directive) of every fenced block, in order."""
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    out, i, directive = [], 0, None
    while i < len(lines):
        m = FENCE.match(lines[i])
        if m is None:
            d = DIRECTIVE.match(lines[i])
            if d:
                directive = (d.group(1), d.group(2))
            elif lines[i].strip():
                directive = None
            i += 1
            continue
        indent, info, start, body = m.group(1), m.group(2), i + 1, []
        i += 1
        while i < len(lines) and lines[i].strip() != "```":
            line = lines[i]
            body.append(line[len(indent):] if line.startswith(indent) else line.lstrip())
            i += 1
        if i == len(lines):
            raise SystemExit(f"{path}:{start}: code block never closed")
        out.append((info, start, body, directive))
        directive = None
        i += 1
    return out


def matches(expected, actual):
    """Whether `actual` lines match `expected` with [...] wildcards (module docstring)."""
    if not expected:
        return not actual
    head = expected[0]
    if head == "[...]":
        return any(matches(expected[1:], actual[k:]) for k in range(len(actual) + 1))
    if not actual:
        return False
    if head.endswith(" [...]"):
        ok = actual[0].startswith(head[: -len(" [...]")])
    else:
        ok = actual[0] == head
    return ok and matches(expected[1:], actual[1:])


def console_commands(body):
    """[(command, expected lines, exit status)] of a console block."""
    commands, i = [], 0
    while i < len(body):
        line = body[i]
        if not line.startswith("$ "):
            raise ValueError(f"line {i + 1} of the block is output before any `$ ` command")
        command = line[2:]
        while command.endswith("\\"):
            i += 1
            command = command + "\n" + body[i]
        i += 1
        expected = []
        while i < len(body) and not body[i].startswith("$ "):
            expected.append(body[i].rstrip())
            i += 1
        status = 0
        if expected and re.fullmatch(r"\[exit \d+\]", expected[-1]):
            status = int(expected[-1][6:-1])
            expected.pop()
        while expected and not expected[-1]:
            expected.pop()
        commands.append((command, expected, status))
    return commands


def run(command, cwd, env, shell=True, stdin=None):
    result = subprocess.run(command, cwd=cwd, env=env, shell=shell, executable="/bin/bash" if shell else None,
                            input=stdin, capture_output=True, text=True, timeout=TIMEOUT_SECONDS)
    return result.returncode, result.stdout, result.stderr


def output_lines(text):
    lines = [line.rstrip() for line in text.split("\n")]
    while lines and not lines[-1]:
        lines.pop()
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("doc")
    parser.add_argument("--zcheck", required=True)
    parser.add_argument("--python-path", required=True)
    parser.add_argument("--models", required=True)
    parser.add_argument("--source", required=True)
    parser.add_argument("--keep", action="store_true", help="keep the working folder and print it")
    args = parser.parse_args()

    work = tempfile.mkdtemp(prefix="zcheck-doc-")
    os.symlink(os.path.join(os.path.abspath(args.source), "examples"), os.path.join(work, "examples"))
    os.symlink(os.path.abspath(args.models), os.path.join(work, "models"))
    bin_dir = os.path.join(work, ".bin")
    os.mkdir(bin_dir)
    os.symlink(os.path.abspath(args.zcheck), os.path.join(bin_dir, "zcheck"))
    env = dict(os.environ)
    env["PATH"] = bin_dir + os.pathsep + env.get("PATH", "")
    env["PYTHONPATH"] = os.path.abspath(args.python_path)
    env["ZCHECK_MODELS_DIR"] = os.path.abspath(args.models)
    env["LC_ALL"] = "C.UTF-8"

    failures, examples = [], 0
    found = blocks(args.doc)
    for n, (info, start, body, directive) in enumerate(found):
        where = f"{args.doc}:{start}"
        text = "\n".join(body) + "\n"
        try:
            if info == "console":
                for command, expected, status in console_commands(body):
                    examples += 1
                    code, out, err = run(command, work, env)
                    actual = output_lines(out) + output_lines(err)
                    if code != status:
                        failures.append(f"{where}: `{command}` exited {code}, expected {status}\n{err.strip()}")
                    elif expected and not matches(expected, actual):
                        failures.append(f"{where}: `{command}` printed\n" + "\n".join(actual)
                                        + "\n--- expected ---\n" + "\n".join(expected))
            elif info == "sh":
                examples += 1
                code, out, err = run(["bash", "-c", "set -euo pipefail\n" + text], work, env, shell=False)
                if code != 0:
                    failures.append(f"{where}: the sh block exited {code}\n{(out + err).strip()}")
            elif info == "python":
                examples += 1
                code, out, err = run([sys.executable, "-c", text], work, env, shell=False)
                if code != 0:
                    failures.append(f"{where}: the python block exited {code}\n{err.strip()}")
                elif n + 1 < len(found) and found[n + 1][0] == "output":
                    expected = [line.rstrip() for line in found[n + 1][2]]
                    if not matches(expected, output_lines(out)):
                        failures.append(f"{where}: the python block printed\n{out.strip()}\n--- expected ---\n"
                                        + "\n".join(expected))
            elif info == "json":
                examples += 1
                json.loads(text)
                if directive and directive[0] == "file":
                    with open(os.path.join(work, directive[1]), "w", encoding="utf-8") as f:
                        f.write(text)
            elif info in ("cpp", "cmake"):
                if not directive or directive[0] != "from":
                    failures.append(f"{where}: a {info} block needs <!-- from: PATH --> naming the file it shows")
                    continue
                examples += 1
                with open(os.path.join(args.source, directive[1]), encoding="utf-8") as f:
                    source = [line.rstrip() for line in f.read().split("\n")]
                k = 0
                for line in (line.rstrip() for line in body):
                    while k < len(source) and source[k] != line:
                        k += 1
                    if k == len(source):
                        failures.append(f"{where}: `{line}` is not in {directive[1]} (in order)")
                        break
                    k += 1
            elif info not in ("", "text", "output"):
                failures.append(f"{where}: unknown block kind '{info}' (console, sh, python, json, cpp, cmake, text, output)")
        except subprocess.TimeoutExpired as e:
            failures.append(f"{where}: timed out after {TIMEOUT_SECONDS} s: {e.cmd}")
        except (ValueError, OSError) as e:
            failures.append(f"{where}: {e}")

    if args.keep:
        print(f"working folder kept: {work}")
    else:
        shutil.rmtree(work, ignore_errors=True)
    for failure in failures:
        print(f"FAIL {failure}\n")
    print(f"{args.doc}: {examples} examples, {len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
