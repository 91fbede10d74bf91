#!/usr/bin/env python3
"""The project's size limits on its C++ core: no file under cpp/ over 900 lines, no function
over 120 lines (a lambda counts inside its function). Prints each breach as file:line and exits
1 when there is one; run by scripts/lint.sh.

Functions are found by matching braces with comments, strings and raw strings blanked out: a
'{' opens a function body when the text before it (back to the last ';', '{' or '}') ends with a
parameter list, optionally followed by const, noexcept, override or a trailing return type, and
does not start with a control statement. Nested bodies (lambdas, local classes) count in their
enclosing function.
"""
import re
import subprocess
import sys
from pathlib import Path

MAX_FILE_LINES = 900
MAX_FUNCTION_LINES = 120

HEADER_END = re.compile(r"\)\s*(const)?\s*(noexcept)?\s*(override)?\s*(->\s*[\w:<>,\s*&]+)?$")
CONTROL = re.compile(r"(if|for|while|switch|catch|do)\b")


def blanked(source):
    """``source`` with comments and string and character literals replaced by spaces (line
    breaks kept, so line numbers hold)."""
    out, i, n = [], 0, len(source)
    while i < n:
        if source.startswith("//", i):
            j = source.find("\n", i)
            j = n if j < 0 else j
        elif source.startswith("/*", i):
            j = source.find("*/", i + 2)
            j = n if j < 0 else j + 2
        elif source.startswith('R"', i) and (i == 0 or not source[i - 1].isalnum()):
            delimiter = re.match(r'R"([^(]*)\(', source[i:]).group(1)
            j = source.find(")" + delimiter + '"', i)
            j = n if j < 0 else j + len(delimiter) + 2
        elif source[i] in "\"'" and not (source[i] == "'" and i > 0 and source[i - 1].isalnum()):
            quote, j = source[i], i + 1
            while j < n and source[j] != quote:
                j += 2 if source[j] == "\\" else 1
            j += 1
        else:
            out.append(source[i])
            i += 1
            continue
        out.append(re.sub(r"[^\n]", " ", source[i:j]))
        i = j
    return "".join(out)


def long_functions(path, limit):
    text = blanked(path.read_text())
    stack = []  # (offset, is a function body, header)
    for m in re.finditer(r"[{}]", text):
        if m.group() == "{":
            before = text[max(0, m.start() - 400):m.start()]
            cut = max(before.rfind(";"), before.rfind("}"), before.rfind("{"))
            header = before[cut + 1:].strip()
            function = (bool(HEADER_END.search(header)) and not CONTROL.match(header)
                        and "=" not in header.split("(")[0])
            inside = any(f for _, f, _ in stack)
            stack.append((m.start(), function and not inside, header))
        elif stack:
            start, function, header = stack.pop()
            if function:
                first = text.count("\n", 0, start) + 1
                last = text.count("\n", 0, m.start()) + 1
                if last - first + 1 > limit:
                    name = " ".join(header.split())[:80]
                    yield first, last - first + 1, name


def main():
    root = Path(__file__).resolve().parent.parent
    files = subprocess.run(["git", "ls-files", "cpp/*.cpp", "cpp/*.hpp"], cwd=root,
                           capture_output=True, text=True, check=True).stdout.split()
    breaches = 0
    for name in files:
        path = root / name
        lines = path.read_text().count("\n")
        if lines > MAX_FILE_LINES:
            print("%s: %d lines (the limit is %d)" % (name, lines, MAX_FILE_LINES))
            breaches += 1
        for line, length, header in long_functions(path, MAX_FUNCTION_LINES):
            print("%s:%d: function of %d lines (the limit is %d): %s"
                  % (name, line, length, MAX_FUNCTION_LINES, header))
            breaches += 1
    return 1 if breaches else 0


if __name__ == "__main__":
    sys.exit(main())
