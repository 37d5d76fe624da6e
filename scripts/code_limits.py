#!/usr/bin/env python3
"""The size floors of STYLE.md on the C++ sources: no file over 600 lines, no function over
120 lines (from the line its declaration starts on to its closing brace, lambdas inside it
included). Usage: scripts/code_limits.py [--list N] [ROOT]. Prints the offenders and exits 1
if there are any; --list N also prints the N longest functions.

How functions are found (no compiler needed): comments, string and character literals and
preprocessor lines are blanked, then the braces are followed with a stack of scopes
(namespace, class, function body, inner block, initializer). A brace opened at namespace or
class scope is a function body when the text since the previous `;`, `{` or `}` holds a
parameter list and is not a namespace, class, struct, union or enum head, nor ends in `=`; a
brace that ends a constructor's member-initializer list (`: a_(x), b_{y}`) is an initializer
and the body's head runs on past it. Lambdas and local classes inside a body are part of it.
"""
import os
import re
import subprocess
import sys

MAX_FILE_LINES = 600
MAX_FUNCTION_LINES = 120
MODULES = ("core", "geometry", "vision", "solver", "output", "cli", "tests", "bench", "fuzz")


def blank_non_code(text):
    """`text` with comments, string/char literals and preprocessor lines replaced by spaces
    (newlines kept, so offsets map to the same lines)."""
    out = list(text)
    i, n = 0, len(text)
    at_line_start = True

    def blank(a, b):
        for k in range(a, b):
            if out[k] != "\n":
                out[k] = " "

    while i < n:
        c = text[i]
        if c == "\n":
            at_line_start = True
            i += 1
            continue
        if at_line_start and c == "#":  # preprocessor line, with continuations
            j = i
            while j < n and not (text[j] == "\n" and text[j - 1] != "\\"):
                if text.startswith("/*", j):
                    end = text.find("*/", j + 2)
                    j = n if end < 0 else end + 2
                    continue
                j += 1
            blank(i, j)
            i = j
            continue
        if not c.isspace():
            at_line_start = False
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            blank(i, j)
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            blank(i, j)
            i = j
        elif c == "R" and text.startswith('"', i + 1) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")) \
                or (c in "uUL8" and re.match(r'(u8|u|U|L)R"', text[i:i + 4]) and (i == 0 or not text[i - 1].isalnum())):
            quote = text.find('"', i)
            paren = text.find("(", quote)
            delimiter = text[quote + 1:paren]
            end = text.find(")" + delimiter + '"', paren)
            j = n if end < 0 else end + len(delimiter) + 2
            blank(i, j)
            i = j
        elif c == '"' or (c == "'" and not (i > 0 and text[i - 1].isalnum())):  # ' after a digit: 1'000
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            blank(i, min(j + 1, n))
            i = j + 1
        else:
            i += 1
    return "".join(out)


def top_level(head):
    """`head` with everything inside (), [] and <...> of templates left out: the text at depth 0."""
    depth, kept = 0, []
    for ch in head:
        if ch in "([":
            depth += 1
        elif ch in ")]":
            depth = max(0, depth - 1)
        elif depth == 0:
            kept.append(ch)
    return "".join(kept)


def classify(head):
    """What a brace opened at namespace or class scope after `head` opens."""
    h = " ".join(head.split())
    h = re.sub(r"^(public|private|protected)\s*:", "", h).strip()
    h = re.sub(r"^template\s*<.*?>\s*(?=[A-Za-z_])", "", h)
    flat = top_level(h)
    if re.match(r"^(inline\s+)?namespace\b", flat) or flat in ("extern", "extern \"C\""):
        return "namespace"
    if re.search(r"(^|\s|typedef\s+)(class|struct|union|enum)\b", flat) and "(" not in h.split(":")[0]:
        return "class"
    if not h or h.endswith("=") or "(" not in h:
        return "init"
    last_paren = h.rfind(")")
    after = h[last_paren + 1:]
    # A member-initializer list: a single ':' after the parameter list, and the brace follows
    # a member name (a_{x}), not the parameter list, a qualifier or a trailing return type.
    if re.search(r"(^|[^:]):([^:]|$)", top_level(h[h.find("("):])) and re.search(r"[\w>]\s*$", h) \
            and "->" not in after and not re.search(r"\)\s*(const|noexcept|override|final|mutable|&|\s)*$", h):
        return "initializer"
    return "function"


def function_name(head):
    h = " ".join(head.split())
    m = re.search(r"(operator\s*(\(\)|[^\s(]+)|~?[A-Za-z_][\w:]*(<[^()]*>)?)\s*\(", h)
    return m.group(1) if m else h[:40]


def functions(text):
    """(first line, last line, name) of every function body at namespace or class scope."""
    code = blank_non_code(text)
    line_of = []
    line = 1
    for ch in code:
        line_of.append(line)
        if ch == "\n":
            line += 1
    stack = []  # (kind, start offset of its head)
    head_start = 0
    found = []
    for i, ch in enumerate(code):
        if ch == ";":
            if not stack or stack[-1][0] in ("namespace", "class"):
                head_start = i + 1
        elif ch == "{":
            outer = stack[-1][0] if stack else "namespace"
            if outer in ("function", "block", "init"):
                stack.append(("block", head_start))
                continue
            head = code[head_start:i]
            kind = classify(head)
            stack.append((kind, head_start))
            if kind != "initializer":
                head_start = i + 1
        elif ch == "}":
            if not stack:
                continue
            kind, start = stack.pop()
            outer = stack[-1][0] if stack else "namespace"
            if kind == "function":
                head = code[start:i]
                first = start + len(head) - len(head.lstrip())
                found.append((line_of[first], line_of[i], function_name(code[start:code.find("{", start)])))
            if kind != "initializer" and outer in ("namespace", "class"):
                head_start = i + 1
    return found


def source_files(root):
    try:
        listed = subprocess.run(["git", "-C", root, "ls-files", "--cached", "--others", "--exclude-standard"],
                                capture_output=True, text=True, check=True).stdout.split()
    except (OSError, subprocess.CalledProcessError):
        listed = [os.path.relpath(os.path.join(d, f), root) for d, _, fs in os.walk(root) for f in fs]
    return sorted(f for f in listed if f.endswith((".cpp", ".h")) and f.split("/")[0] in MODULES
                  and os.path.isfile(os.path.join(root, f)))


def main(argv):
    listing = 0
    if len(argv) > 1 and argv[0] == "--list":
        listing = int(argv[1])
        argv = argv[2:]
    root = argv[0] if argv else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    offenders, all_functions = [], []
    for path in source_files(root):
        with open(os.path.join(root, path), encoding="utf-8", errors="replace") as f:
            text = f.read()
        lines = text.count("\n") + (0 if text.endswith("\n") else 1)
        if lines > MAX_FILE_LINES:
            offenders.append(f"{path}: {lines} lines (at most {MAX_FILE_LINES} per file)")
        for first, last, name in functions(text):
            length = last - first + 1
            all_functions.append((length, path, first, name))
            if length > MAX_FUNCTION_LINES:
                offenders.append(f"{path}:{first}: {name}: {length} lines (at most {MAX_FUNCTION_LINES} per function)")
    for length, path, first, name in sorted(all_functions, reverse=True)[:listing]:
        print(f"{length:5d} {path}:{first} {name}")
    for offender in offenders:
        print(offender)
    print(f"code_limits: {len(all_functions)} functions in {len(source_files(root))} files; "
          f"{len(offenders)} over the limits")
    return 1 if offenders else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
