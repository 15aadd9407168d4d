#!/usr/bin/env python3
"""Functions a reader can hold (issue #36): no library function over 150 lines.

Scans every src/**/*.cc (the library; python/src holds the binding lists and
is outside the rule), finds each function definition at namespace or class
scope by matching braces in the text stripped of comments, strings and
character literals, and counts its lines from the first line of its
signature to its closing brace. A function over the limit fails the test
unless it is on PENDING with the reason it is still long; a PENDING entry
that is no longer long fails too, so the list only shrinks.

Usage: check_function_length.py <source dir> [--list]
"""
import os
import re
import sys

LIMIT = 150

# "file:function": why it is still long. Empty when the rule holds everywhere.
PENDING = {
}


def strip(text):
    """Comments, string and char literals replaced by spaces; newlines kept."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = ")" + m.group(1) + '"'
            j = text.find(end, i) + len(end)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == '"' or (c == "'" and not (i > 0 and text[i - 1].isalnum())):
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(c + " " * (j - i - 1) + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


SCOPE = re.compile(r"\b(namespace|struct|class|union|extern\s+\"C\")\b[^;()]*$|^\s*extern\s*$")


def functions(text):
    """(name, first line, last line) of every function definition."""
    s = strip(text)
    line_of = [0] * (len(s) + 1)
    ln = 1
    for i, ch in enumerate(s):
        line_of[i] = ln
        if ch == "\n":
            ln += 1
    stack = []  # per open brace: True when it opens a scope that holds functions
    last = 0    # end of the last statement, declaration or block at this level
    found = []
    i = 0
    while i < len(s):
        ch = s[i]
        if ch == "{":
            head = s[last:i]
            transparent = all(stack) and bool(SCOPE.search(head.strip().replace("\n", " ")))
            is_function = (all(stack) and not transparent and ")" in head and "(" in head
                           and not re.search(r"=\s*$", head.strip()) and not re.match(r"\s*(enum|return)\b", head))
            if is_function:
                # The function ends at its matching brace.
                depth, j = 0, i
                while j < len(s):
                    if s[j] == "{":
                        depth += 1
                    elif s[j] == "}":
                        depth -= 1
                        if depth == 0:
                            break
                    j += 1
                start = last + len(head) - len(head.lstrip())
                m = re.search(r"([~\w:]+(?:operator\s*\S+)?)\s*\(", head)
                name = m.group(1) if m else "?"
                found.append((name, line_of[start], line_of[j]))
                i = j + 1
                last = i
                continue
            stack.append(transparent or not all(stack) and False)
            last = i + 1
        elif ch == "}":
            if stack:
                stack.pop()
            last = i + 1
        elif ch == ";" or (ch == ":" and re.search(r"\b(public|private|protected)\s*$", s[last:i])):
            last = i + 1
        elif ch == "#" and (i == 0 or s[i - 1] == "\n"):
            j = s.find("\n", i)
            i = len(s) if j < 0 else j
            last = i
            continue
        i += 1
    return found


def main():
    root = sys.argv[1]
    listing = "--list" in sys.argv
    long = {}
    for dirpath, _, files in os.walk(os.path.join(root, "src")):
        for f in sorted(files):
            if not f.endswith(".cc"):
                continue
            path = os.path.join(dirpath, f)
            rel = os.path.relpath(path, root)
            with open(path, encoding="utf-8") as fh:
                for name, a, b in functions(fh.read()):
                    if b - a + 1 > LIMIT:
                        long[f"{rel}:{name}"] = (b - a + 1, a)
    if listing:
        for key, (n, a) in sorted(long.items(), key=lambda kv: -kv[1][0]):
            print(f"{n:5d}  {key} (line {a})")
        return 0
    bad = [f"{k}: {n} lines from line {a} (limit {LIMIT}); split it along its stages"
           for k, (n, a) in sorted(long.items()) if k not in PENDING]
    gone = [f"{k}: no longer over {LIMIT} lines; take it off PENDING in {os.path.basename(__file__)}"
            for k in sorted(PENDING) if k not in long]
    for line in bad + gone:
        print(line)
    print(f"{len(long)} functions over {LIMIT} lines, {len(PENDING)} pending")
    return 1 if bad or gone else 0


if __name__ == "__main__":
    sys.exit(main())
