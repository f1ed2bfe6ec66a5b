#!/usr/bin/env python3
"""Lists the C++ functions in src/ whose bodies are longer than a limit (120 lines by default).

Usage: scripts/long_functions.py [--max LINES] [--top N] [ROOT...]
       scripts/long_functions.py --self-test
  ROOT: folders or files to scan (default: the repository's src/); *.cpp and *.hpp are read.
  --max: the longest body allowed, in lines from its opening brace to its closing one.
  --top: also print the N longest functions, whatever their length.
  --self-test: checks the scan on a sample of the constructs it must see through.
Exits 1, listing them, when a function is longer than --max; 0 otherwise.

A brace-matching scan, not a parser: comments, string and character literals (raw strings
included) and preprocessor lines are blanked first, then every brace at namespace or class scope
is classified from the text before it (a namespace, a class, or a function: a parameter list then
only qualifiers). A function's body, lambdas and local classes included, counts once, as the
enclosing function; a lambda at namespace scope counts as a function of its own.
"""
import argparse
import pathlib
import re
import sys

QUALIFIERS = re.compile(r"^(\s*(const|volatile|noexcept|override|final|mutable|try|&&|&))*\s*(->[^;{}=]+)?\s*$")
CLASS_KEY = re.compile(r"\b(class|struct|union|enum)\b")
CTOR_INIT = re.compile(r"\)\s*(noexcept\s*)?:(?!:)")
IDENT_END = re.compile(r"[A-Za-z0-9_>]\s*$")


def blank(text):
    """The text with comments, literals and preprocessor lines replaced by spaces (newlines kept)."""
    out = []
    i, n = 0, len(text)
    line_start = True
    while i < n:
        c = text[i]
        if line_start and c == "#":  # a preprocessor line, with its continuations
            while i < n and text[i] != "\n":
                if text[i] == "\\" and i + 1 < n and text[i + 1] == "\n":
                    out.append(" \n")
                    i += 2
                    continue
                out.append(" ")
                i += 1
            continue
        if c == "\n":
            line_start = True
            out.append(c)
            i += 1
            continue
        if not c.isspace():
            line_start = False
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
        elif c == "R" and i + 1 < n and text[i + 1] == '"' and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_") or text[i - 2:i] == "u8" or text[i - 1] in "LuU"):
            open_paren = text.find("(", i + 2)
            delim = text[i + 2:open_paren]
            j = text.find(")" + delim + '"', open_paren)
            j = n if j < 0 else j + len(delim) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == '"' or (c == "'" and not digit_separator(text, i)):
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(" " * (j - i))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def digit_separator(text, i):
    """A quote inside a number (1'000'000), not the start of a character literal."""
    j = i
    while j > 0 and (text[j - 1].isalnum() or text[j - 1] in "_."):
        j -= 1
    word = text[j:i]
    return bool(word) and word[0].isdigit()


def function_name(header):
    """The name before the parameter list of a function header, or the variable a lambda is bound to."""
    end = header.rfind(")")
    depth = 0
    for k in range(end, -1, -1):
        if header[k] == ")":
            depth += 1
        elif header[k] == "(":
            depth -= 1
            if depth == 0:
                before = header[:k].rstrip()
                if before.endswith("]"):  # a lambda: the name it is given
                    m = re.search(r"([A-Za-z_]\w*)\s*=\s*\[[^\]]*\]$", before)
                    return (m.group(1) if m else "lambda") + " (lambda)"
                m = re.search(r"((?:[A-Za-z_~]\w*\s*(?:<[^<>]*>)?\s*::\s*)*(?:operator\s*\S+|~?[A-Za-z_]\w*))$", before)
                return re.sub(r"\s+", "", m.group(1)) if m else before.split()[-1] if before.split() else "?"
    return "?"


def functions(path):
    """(name, first line, body lines) of every function defined at namespace or class scope in `path`."""
    text = blank(path.read_text(encoding="utf-8", errors="replace"))
    found = []
    scopes = [("namespace", "")]  # what each open brace opened: (namespace or class, the class's name)
    header, header_line = "", None
    line = 1
    i, n = 0, len(text)

    def skip_block(i, line):
        """From an opening brace, past its matching closing brace: (index after it, line of it)."""
        depth = 0
        while i < n:
            ch = text[i]
            if ch == "\n":
                line += 1
            elif ch == "{":
                depth += 1
            elif ch == "}":
                depth -= 1
                if depth == 0:
                    return i + 1, line
            i += 1
        return n, line

    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
        if c == "{":
            h = header.strip()
            is_ctor = CTOR_INIT.search(h) is not None
            if is_ctor and IDENT_END.search(h):  # a member's braced initialiser: part of the header
                j, line = skip_block(i, line)
                header += " {} "
                i = j
                continue
            close = h.rfind(")")
            if "(" in h and close >= 0 and (QUALIFIERS.match(h[close + 1:]) or is_ctor):
                start = line
                j, end = skip_block(i, line)
                name = function_name(h[:close + 1] if not is_ctor else h[:CTOR_INIT.search(h).start() + 1])
                if scopes[-1][0] == "class":
                    name = scopes[-1][1] + "::" + name
                found.append((name, header_line or start, end - start + 1))
                line = end
                i = j
                header, header_line = "", None
                continue
            if re.search(r"\bnamespace\b", h) or re.fullmatch(r"extern\s*", h):
                scopes.append(("namespace", ""))
            elif CLASS_KEY.search(h) and "=" not in h and "(" not in h and not re.search(r"\benum\b", h):
                m = re.search(r"\b(?:class|struct|union)\s+(?:\[\[[^\]]*\]\]\s*)?([A-Za-z_]\w*)", h)
                scopes.append(("class", m.group(1) if m else "?"))
            else:  # an initialiser, an enum body: no function inside
                j, line = skip_block(i, line)
                header += " {} "
                i = j
                continue
            header, header_line = "", None
        elif c == "}":
            if len(scopes) > 1:
                scopes.pop()
            header, header_line = "", None
        elif c == ";":
            header, header_line = "", None
        elif c == ":" and scopes[-1][0] == "class" and re.fullmatch(r"\s*(public|private|protected)\s*", header):
            header, header_line = "", None
        else:
            if header_line is None and not c.isspace():
                header_line = line
            header += c
        i += 1
    return found


SAMPLE = r'''
#define BLOCK { {
namespace a { namespace {
const char* text = "} {";  // } a comment {
const auto raw = R"x(} ) {)x";
char brace = '{';
int million = 1'000'000;
struct Grid {
  Grid(int n) : cells_{n}, rows_(n) {
    rows_ += 1;
  }
  int size() const { return rows_; }
 private:
  int cells_{0}, rows_ = 0;
};
enum class Kind { x, y };
const auto twice = [](int x) {
  return 2 * x;
};
/* { */
template <class T>
auto pick(T t) -> T {
  auto f = [&](int k) { return k; };
  if (t) {
    for (;;) {}
  }
  return f(t);
}
}  // namespace
}  // namespace a
'''


def self_test():
    """The scan of SAMPLE finds its four functions (the lambda inside pick is part of pick), at the right lines and lengths."""
    import tempfile
    with tempfile.TemporaryDirectory() as folder:
        sample = pathlib.Path(folder) / "sample.cpp"
        sample.write_text(SAMPLE)
        found = functions(sample)
    want = [("Grid::Grid", 9, 3), ("Grid::size", 12, 1), ("twice (lambda)", 17, 3), ("pick", 21, 7)]
    if found != want:
        print(f"self-test: found {found}, want {want}", file=sys.stderr)
        return 1
    print("self-test: ok")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("roots", nargs="*", type=pathlib.Path)
    parser.add_argument("--max", type=int, default=120)
    parser.add_argument("--top", type=int, default=0)
    parser.add_argument("--self-test", action="store_true")
    args = parser.parse_args()
    if args.self_test:
        return self_test()
    repo = pathlib.Path(__file__).resolve().parent.parent
    roots = args.roots or [repo / "src"]
    files = []
    for root in roots:
        if not root.exists():
            print(f"{root}: no such file or folder", file=sys.stderr)
            return 2
        files += [root] if root.is_file() else sorted(p for p in root.rglob("*") if p.suffix in (".cpp", ".hpp"))
    shown = lambda p: str(p.resolve().relative_to(repo)) if p.resolve().is_relative_to(repo) else str(p)
    every = [(lines, shown(p), first, name) for p in files for name, first, lines in functions(p)]
    every.sort(key=lambda f: (-f[0], f[1], f[2]))
    for lines, path, first, name in every[:args.top]:
        print(f"{path}:{first}: {name}: {lines} lines")
    long = [f for f in every if f[0] > args.max]
    for lines, path, first, name in long:
        print(f"{path}:{first}: {name}: {lines} lines, longer than {args.max}", file=sys.stderr)
    if long:
        print(f"{len(long)} function(s) longer than {args.max} lines", file=sys.stderr)
        return 1
    print(f"{len(every)} functions in {len(files)} files, none longer than {args.max} lines")
    return 0


if __name__ == "__main__":
    sys.exit(main())
