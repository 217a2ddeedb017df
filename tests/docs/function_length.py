#!/usr/bin/env python3
"""No function in the benches is longer than a screen (ctest: docs/bench_function_length).

A bench is a sweep (configurations x measures -> table, bench/sweep.h), so its
functions stay short. A function here counts from the first line of its
signature to its closing brace; lambdas and local classes count with the
function they sit in. Member functions inside a class body are measured one
by one. Comments, strings and character literals are blanked before the scan,
so braces inside them do not count.

Functions not yet rewritten as sweeps are listed in PENDING with their
length today: they may shrink, not grow, and an entry that fits the limit
must leave the list. Before the scan, the scanner checks itself on SAMPLE.

usage: function_length.py MAX_LINES FILE_OR_DIR...   (prints every long one)
"""
import os
import re
import sys

SKIP_BLOCK = re.compile(r"\b(namespace|extern\s*\"C\")\b[^;{}]*$")
TYPE_BLOCK = re.compile(r"\b(class|struct|union|enum)\b[^;{}()=]*$")

# "file:function" -> its length (lines) before it became a sweep.
PENDING = {  # empty: every bench function fits
}

# Braces in comments, strings and lambdas; a signature over two lines; a
# member function in a class body: (name, first line, last line).
SAMPLE = (
    'namespace a {\nstruct S {\n  int f() const { return 1; }\n  int g(int x)\n'
    '      const {\n    auto l = [&]() { return "}}"; };\n    return x;\n  }\n};\n'
    'int Long(int a,\n         int b) {\n  // }\n  if (a) {\n    return b;\n  }\n'
    '  return \'}\';\n}\nint v[] = {1, 2};\n}  // namespace a\n')
SAMPLE_FUNCTIONS = [("f", 3, 3), ("g", 4, 8), ("Long", 10, 17)]


def blank(text):
    """`text` with comments, strings and char literals replaced by spaces (newlines kept)."""
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
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not text[i - 1].isalnum()):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = text.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum():  # digit separator 1'000
                out.append(c)
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(c + " " * (min(j, n) - i - 1) + (c if j < n else ""))
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(text):
    """(name, first_line, last_line) of every function body in `text` (1-based lines)."""
    code = blank(text)
    found = []
    # Stack of (kind, head_start) for open braces: "scope" (namespace, class
    # body: functions inside are measured), "function", or "other" (inside a
    # function, or an initializer).
    stack = []
    head_start = 0  # where the current declaration's text began
    i = 0
    for i, c in enumerate(code):
        in_function = any(kind == "function" for kind, _ in stack)
        if c == "{":
            if in_function:
                stack.append(("other", i))
                continue
            head = code[head_start:i]
            stripped = head.strip()
            if SKIP_BLOCK.search(stripped) or TYPE_BLOCK.search(stripped) or not stripped:
                stack.append(("scope", head_start))
            elif ")" in stripped and not re.search(r"=\s*$", stripped):
                stack.append(("function", head_start + len(head) - len(head.lstrip())))
            else:
                stack.append(("other", head_start))
            head_start = i + 1
        elif c == "}":
            kind, start = stack.pop() if stack else ("scope", 0)
            if kind == "function":
                first = code.count("\n", 0, start) + 1
                last = code.count("\n", 0, i) + 1
                head = code[start:code.index("{", start)]
                name = re.findall(r"([~\w:]+)\s*\(", head)
                found.append((name[0] if name else "?", first, last))
            if not any(k == "function" for k, _ in stack):
                head_start = i + 1
        elif c == ";" and not in_function:
            head_start = i + 1
        elif c == ":" and not in_function and re.search(
                r"\b(public|private|protected)\s*$", code[head_start:i]):
            head_start = i + 1
    return found


def main():
    limit = int(sys.argv[1])
    files = []
    for arg in sys.argv[2:]:
        if os.path.isdir(arg):
            files += sorted(os.path.join(arg, f) for f in os.listdir(arg)
                            if f.endswith((".cc", ".h")))
        else:
            files.append(arg)
    if functions(SAMPLE) != SAMPLE_FUNCTIONS:
        print(f"scanner broken: {functions(SAMPLE)} != {SAMPLE_FUNCTIONS}")
        return 1
    long_ones = []
    for path in files:
        with open(path, encoding="utf-8") as f:
            for name, first, last in functions(f.read()):
                lines = last - first + 1
                key = f"{os.path.basename(path)}:{name}"
                ceiling = PENDING.get(key, limit)
                if key in PENDING and lines <= limit:
                    long_ones.append(f"{path}:{first}: {name} is {lines} lines: "
                                     "remove it from PENDING")
                elif lines > ceiling:
                    long_ones.append(f"{path}:{first}: {name} is {lines} lines (at most {ceiling})")
    for line in long_ones:
        print(line)
    if not files:
        print("no files to scan")
        return 1
    return 1 if long_ones else 0


if __name__ == "__main__":
    sys.exit(main())
