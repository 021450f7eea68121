#!/usr/bin/python3
"""Lists the C++ functions in src/ longer than a limit (DESIGN.md: no function over 120
lines); exits 1 if there is one. A function is a brace block at namespace or class level whose
head holds a parameter list; lambdas and local classes count towards the function that holds
them. Comments and string literals are blanked before braces are counted.

usage: tests/style/function_length.py [--limit 120] [--all] [SRC_DIR]
"""
import os, re, sys

CONTROL = re.compile(r"^\s*(if|for|while|switch|catch|do|else|try)\b")


def blank(text):
    """The text with comments, string and character literals replaced by spaces (newlines kept)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i)); i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j])); i = j
        elif text.startswith('R"', i) and re.match(r'R"([^(\s]*)\(', text[i:]):
            delim = re.match(r'R"([^(\s]*)\(', text[i:]).group(1)
            j = text.find(")" + delim + '"', i)
            j = n if j < 0 else j + len(delim) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j])); i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(" " * (j + 1 - i)); i = j + 1
        else:
            out.append(c); i += 1
    return "".join(out)


def functions(path):
    """(name, first line, line count) of every function body in the file."""
    text = blank(open(path, encoding="utf-8").read())
    found, stack, head_start = [], [], 0  # stack: kinds of the open braces
    for i, c in enumerate(text):
        if c == "{":
            head = text[head_start:i]
            in_function = any(k[0] == "function" for k in stack)
            is_function = (not in_function and ")" in head and not CONTROL.match(head)
                           and not re.search(r"\b(namespace|class|struct|enum|union)\b[^)]*$", head))
            kind = "function" if is_function else ("block" if in_function else "scope")
            if is_function:
                name = re.findall(r"([~\w:]+)\s*\(", head)
                stack.append((kind, name[0] if name else "?", text.count("\n", 0, i) + 1))
            else:
                stack.append((kind,))
            head_start = i + 1
        elif c == "}":
            if stack:
                top = stack.pop()
                if top[0] == "function":
                    end = text.count("\n", 0, i) + 1
                    found.append((top[1], top[2], end - top[2] + 1))
            head_start = i + 1
        elif c == ";" and not any(k[0] == "function" for k in stack):
            head_start = i + 1
    return found


def main():
    args = sys.argv[1:]
    limit, show_all = 120, "--all" in args
    if "--limit" in args:
        limit = int(args[args.index("--limit") + 1])
    rest = [a for a in args if not a.startswith("--") and not a.isdigit()]
    src = rest[0] if rest else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "src")
    long_ones = []
    for root, _, files in os.walk(src):
        for f in sorted(files):
            if f.endswith((".cpp", ".h")):
                p = os.path.join(root, f)
                long_ones += [(n, os.path.relpath(p, src), name, line) for name, line, n in functions(p)
                              if show_all or n > limit]
    for n, p, name, line in sorted(long_ones, reverse=True):
        print("%5d lines  %s:%d  %s" % (n, p, line, name))
    if not show_all and long_ones:
        print("%d functions over %d lines" % (len(long_ones), limit))
    return 1 if long_ones and not show_all else 0


if __name__ == "__main__":
    sys.exit(main())
