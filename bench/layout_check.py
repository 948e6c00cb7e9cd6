#!/usr/bin/env python3
"""Layout check (issue 18): big files and import loops inside the workspace's crates. Python 3 standard library only.

    bench/layout_check.py [ROOT] [--max-lines N]      # ROOT: the workspace (default: this script's ../)

Prints what it finds and exits 1 if anything is found, 0 if nothing (2 on bad arguments).

1. Big files. Every `.rs` file of the workspace longer than N lines (default 500), except those under a `tests/`
   folder (integration tests) and under `target/`. Lines are counted as `wc -l` does, unit tests included.

2. Import loops. Each crate root (`src/lib.rs`, `src/main.rs`, `src/bin/*.rs`) is read as a tree of modules, from its
   `mod x;` declarations (file `x.rs` or `x/mod.rs`) and inline `mod x { ... }` blocks. Modules under
   `#[cfg(test)]` (unit tests) are left out: test code does not shape the layout. A library and the binary built
   on it are different crates; the binary's use of the library is not an edge.

   An edge A -> B is one reference in A's own code (comments and string literals stripped) to an item of module B:
   a `use` declaration (`use crate::..`, `use super::..`, `use self::..`, `use child::..`, groups and renames
   expanded), or a path in the code starting with `crate::`, `super::` or `self::`. A path is resolved to the module
   that defines the item: through declared modules, then through the names the module reached binds with `use`
   (a re-export `pub use b::Item` or a private import) and its glob imports, so that `use super::Item`, where the
   parent re-exports `b::Item`, is an edge to `b`.

   Two kinds of edge are the ordinary Rust pattern and are not counted: A -> an ancestor of A (a child using its
   parent's items, `use super::*`), and A -> a descendant of A (a parent declaring, re-exporting or using its
   children). Every other edge runs between two branches of the tree: with P the nearest common ancestor of A and
   B, it is lifted to the edge a -> b between the children a and b of P that hold A and B (for siblings, a = A and
   b = B). A LOOP is a cycle among the children of one module P in these lifted edges: each member, or something
   inside it, uses another member, around and back. So `output::vtk` <-> `output::vtu` is a loop, and so is
   `scene::validate` -> `sizing` with `sizing` -> `scene::schema` (lifted: scene <-> sizing), while `output` ->
   `output::vtk` -> `output` (parent and child) is not. An item defined in an ancestor is not followed further
   (the parent is the place for what its children share), even when that item itself uses another child. A module
   that defines a trait and also names its implementations, sibling modules that import the trait, is a loop; the
   usual ways out are the trait in the parent, or the choice among implementations in a third module.
   Each loop is printed with the edges that make it, as `file:line: the reference`.
"""

import os
import re
import sys
from collections import defaultdict

IDENT = r"[A-Za-z_][A-Za-z0-9_]*"
ITEM_KINDS = r"(?:fn|struct|enum|trait|type|const|static|union|mod)"


# ----------------------------------------------------------------------------------------------------------------
# Source text


def strip(text):
    """The text with comments, string and char literals blanked (newlines kept, so line numbers stay)."""
    out = []
    i, n = 0, len(text)

    def blank(s):
        return "".join("\n" if c == "\n" else " " for c in s)

    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(blank(text[i:j]))
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(blank(text[i:j]))
            i = j
        elif re.match(r'(?:br|r)#*"', text[i:i + 12]) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'(?:br|r)(#*)"', text[i:])
            end = '"' + m.group(1)
            j = text.find(end, i + m.end())
            j = n if j < 0 else j + len(end)
            out.append(blank(text[i:j]))
            i = j
        elif c == '"' or (c == "b" and text.startswith('b"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_"))):
            j = i + (2 if c == "b" else 1)
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(blank(text[i:j]))
            i = j
        elif c == "'":
            # A char literal ('a', '\n', '\u{1F600}') or a lifetime ('a, 'static).
            if text.startswith("\\", i + 1):
                j = text.find("'", i + 2)
                j = n if j < 0 else j + 1
                out.append(blank(text[i:j]))
                i = j
            elif i + 2 < n and text[i + 2] == "'":
                out.append("   ")
                i += 3
            else:
                out.append(c)
                i += 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def matching_brace(text, open_at):
    depth = 0
    for j in range(open_at, len(text)):
        if text[j] == "{":
            depth += 1
        elif text[j] == "}":
            depth -= 1
            if depth == 0:
                return j
    return len(text) - 1


def is_test_only(text, at):
    """Whether the item starting at `at` carries `#[cfg(test)]` (looked for back to the previous item's end)."""
    k = max(text.rfind(";", 0, at), text.rfind("}", 0, at), text.rfind("{", 0, at))
    return re.search(r"#\s*\[\s*cfg\s*\(\s*test\s*\)\s*\]", text[k + 1:at]) is not None


# ----------------------------------------------------------------------------------------------------------------
# Module tree


class Module:
    def __init__(self, path, file, text, start, end, dir_for_children):
        self.path = path  # tuple of names from the crate root
        self.file = file
        self.text = text  # stripped text of the whole file
        self.start, self.end = start, end  # this module's span in text
        self.dir = dir_for_children
        self.children = {}  # name -> Module
        self.holes = []  # spans of inline child modules (their code is theirs)
        self.uses = []  # (line, full path segments, bound name or None, is_glob)

    def own_code(self):
        """(offset, text) pieces of this module's code, inline children left out."""
        pieces, at = [], self.start
        for a, b in sorted(self.holes):
            pieces.append((at, self.text[at:a]))
            at = b
        pieces.append((at, self.text[at:self.end]))
        return pieces

    def line(self, offset):
        return self.text.count("\n", 0, offset) + 1


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def build_tree(root_file):
    text = strip(read(root_file))
    root = Module((), root_file, text, 0, len(text), os.path.dirname(root_file))
    modules = {(): root}
    _children(root, modules)
    return modules


def _children(m, modules):
    text = m.text
    pos = m.start
    pattern = re.compile(r"\bmod\s+(" + IDENT + r")\s*([;{])")
    while True:
        hit = pattern.search(text, pos, m.end)
        if not hit:
            break
        name, kind = hit.group(1), hit.group(2)
        test_only = is_test_only(text, hit.start())
        if kind == "{":
            close = matching_brace(text, hit.end() - 1)
            m.holes.append((hit.start(), close + 1))
            pos = close + 1
            if test_only:
                continue
            child = Module(m.path + (name,), m.file, text, hit.end(), close, os.path.join(m.dir, name))
            m.children[name] = child
            modules[child.path] = child
            _children(child, modules)
        else:
            pos = hit.end()
            if test_only:
                continue
            candidates = [os.path.join(m.dir, name + ".rs"), os.path.join(m.dir, name, "mod.rs")]
            file = next((c for c in candidates if os.path.isfile(c)), None)
            if file is None:
                continue
            ctext = strip(read(file))
            cdir = os.path.dirname(file) if file.endswith("mod.rs") else os.path.join(m.dir, name)
            child = Module(m.path + (name,), file, ctext, 0, len(ctext), cdir)
            m.children[name] = child
            modules[child.path] = child
            _children(child, modules)


# ----------------------------------------------------------------------------------------------------------------
# `use` declarations and paths


def split_top(s, sep=","):
    parts, depth, cur = [], 0, []
    for c in s:
        if c == "{":
            depth += 1
        elif c == "}":
            depth -= 1
        if c == sep and depth == 0:
            parts.append("".join(cur))
            cur = []
        else:
            cur.append(c)
    parts.append("".join(cur))
    return [p.strip() for p in parts if p.strip()]


def expand_use(tree, prefix=()):
    """`a::{b, c::d as e, f::*}` (renames written `d@e`) -> [(segments, bound name, is_glob)]."""
    tree = re.sub(r"\s+", "", tree)
    if tree.startswith("::"):
        tree = tree[2:]
    brace = tree.find("{")
    if brace >= 0:
        head = tree[:brace].rstrip(":")
        inner = tree[brace + 1:tree.rfind("}")]
        segs = prefix + tuple(s for s in head.split("::") if s)
        out = []
        for part in split_top(inner):
            if part == "self":
                out.append((segs, segs[-1] if segs else None, False))
            else:
                out.extend(expand_use(part, segs))
        return out
    body, _, alias = tree.partition("@")
    segs = prefix + tuple(s for s in body.split("::") if s)
    if segs and segs[-1] == "*":
        return [(segs[:-1], None, True)]
    if segs and segs[-1] == "self":
        segs = segs[:-1]
    return [(segs, alias or (segs[-1] if segs else None), False)]


USE = re.compile(r"\buse\s+([^;]+);")
PATH = re.compile(r"(?<![\w$:])((?:crate|super|self)(?:\s*::\s*" + IDENT + r")+)")


def collect_uses(modules):
    for m in modules.values():
        for offset, code in m.own_code():
            for hit in USE.finditer(code):
                # `as` is told apart from the names around it before whitespace is squeezed out.
                body = re.sub(r"\s+as\s+", "@", hit.group(1))
                for segs, bound, glob in expand_use(body):
                    if segs:
                        m.uses.append((m.line(offset + hit.start()), segs, bound, glob, hit.group(0).strip()))


def defines(m, name):
    pattern = r"\b" + ITEM_KINDS + r"\s+" + re.escape(name) + r"\b|\bmacro_rules!\s*" + re.escape(name) + r"\b"
    return any(re.search(pattern, code) for _, code in m.own_code())


def start_of(modules, m, segs):
    """The module a path's first segments name, and the rest; None for a path outside the crate."""
    first = segs[0]
    if first == "crate":
        return modules[()], segs[1:]
    if first in ("self", "super"):
        cur, rest = m.path, list(segs)
        while rest and rest[0] in ("self", "super"):
            if rest.pop(0) == "super":
                if not cur:
                    return None
                cur = cur[:-1]
        return modules[cur], tuple(rest)
    if first in m.children:  # `use child::Item` (2018 uniform paths)
        return m.children[first], segs[1:]
    return None


def resolve(modules, m, segs, depth=0):
    """The module that defines the item a path names (from module m), or None when it is outside the crate."""
    if not segs or depth > 12:
        return None
    found = start_of(modules, m, segs)
    if found is None:
        # A name m imported (`use crate::a; a::f()`).
        for _, usegs, bound, glob, _ in m.uses:
            if not glob and bound == segs[0]:
                return resolve(modules, m, usegs + tuple(segs[1:]), depth + 1)
        return None
    cur, rest = found
    rest = list(rest)
    while rest and rest[0] in cur.children:
        cur = cur.children[rest.pop(0)]
    if not rest:
        return cur
    name = rest[0]
    if defines(cur, name):
        return cur
    for _, usegs, bound, glob, _ in cur.uses:
        if not glob and bound == name:
            target = resolve(modules, cur, usegs + tuple(rest[1:]), depth + 1)
            return target or cur
    for _, usegs, bound, glob, _ in cur.uses:
        if glob:
            g = resolve(modules, cur, usegs, depth + 1)
            if g is not None and g is not cur and (defines(g, name) or name in g.children):
                return resolve(modules, g, ("self",) + tuple(rest), depth + 1) or g
    return cur


def is_ancestor(a, b):
    return len(a) < len(b) and b[: len(a)] == a


def edges_of(modules):
    """Counted edges, lifted: {parent path: {(a, b): [witness, ...]}}."""
    lifted = defaultdict(lambda: defaultdict(list))
    for m in modules.values():
        refs = [(line, segs, text) for line, segs, _, _, text in m.uses]
        for offset, code in m.own_code():
            # The paths of `use` declarations are read above.
            code = USE.sub(lambda h: re.sub(r"[^\n]", " ", h.group(0)), code)
            for hit in PATH.finditer(code):
                segs = tuple(s.strip() for s in hit.group(1).split("::"))
                refs.append((m.line(offset + hit.start()), segs, hit.group(1)))
        for line, segs, text in refs:
            t = resolve(modules, m, segs)
            if t is None or t is m or is_ancestor(t.path, m.path) or is_ancestor(m.path, t.path):
                continue
            k = 0
            while m.path[k] == t.path[k]:
                k += 1
            parent, a, b = m.path[:k], m.path[k], t.path[k]
            where = "%s:%d: %s" % (m.file, line, re.sub(r"\s+", " ", text))
            witness = ("::".join(m.path), "::".join(t.path), where)
            if witness not in lifted[parent][(a, b)]:
                lifted[parent][(a, b)].append(witness)
    return lifted


def cycles(nodes_edges):
    """Strongly connected components with more than one member (Tarjan)."""
    graph = defaultdict(set)
    for a, b in nodes_edges:
        graph[a].add(b)
        graph.setdefault(b, set())
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


# ----------------------------------------------------------------------------------------------------------------
# The workspace


def crates(root):
    found = []
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames[:] = sorted(d for d in dirnames if d not in ("target", ".git", "node_modules") and not d.startswith("."))
        if "Cargo.toml" in filenames and os.path.isdir(os.path.join(dirpath, "src")):
            if re.search(r"^\s*\[package\]", read(os.path.join(dirpath, "Cargo.toml")), re.M):
                found.append(dirpath)
    return found


def crate_roots(crate_dir):
    src = os.path.join(crate_dir, "src")
    roots = []
    for name, label in (("lib.rs", "lib"), ("main.rs", "bin")):
        if os.path.isfile(os.path.join(src, name)):
            roots.append((label, os.path.join(src, name)))
    bins = os.path.join(src, "bin")
    if os.path.isdir(bins):
        for f in sorted(os.listdir(bins)):
            if f.endswith(".rs"):
                roots.append(("bin " + f[:-3], os.path.join(bins, f)))
            elif os.path.isfile(os.path.join(bins, f, "main.rs")):
                roots.append(("bin " + f, os.path.join(bins, f, "main.rs")))
    return roots


def big_files(root, limit):
    out = []
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames[:] = sorted(
            d for d in dirnames if d not in ("target", ".git", "tests", "node_modules") and not d.startswith(".")
        )
        for f in filenames:
            if f.endswith(".rs"):
                p = os.path.join(dirpath, f)
                with open(p, "rb") as fh:
                    lines = fh.read().count(b"\n")
                if lines > limit:
                    out.append((lines, os.path.relpath(p, root)))
    return sorted(out, key=lambda x: (-x[0], x[1]))


def main(argv):
    args = list(argv)
    limit = 500
    if "--max-lines" in args:
        i = args.index("--max-lines")
        try:
            limit = int(args[i + 1])
        except (IndexError, ValueError):
            print("layout_check: --max-lines needs a number", file=sys.stderr)
            return 2
        del args[i:i + 2]
    if len(args) > 1 or any(a.startswith("-") for a in args):
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    root = os.path.abspath(args[0] if args else os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    os.chdir(root)
    problems = 0

    big = big_files(".", limit)
    print("files over %d lines (outside tests/): %d" % (limit, len(big)))
    for lines, path in big:
        print("  %5d  %s" % (lines, path))
    problems += len(big)

    loops = []
    for crate in crates("."):
        for label, root_file in crate_roots(os.path.relpath(crate, ".")):
            modules = build_tree(root_file)
            collect_uses(modules)
            for parent, edges in sorted(edges_of(modules).items()):
                for comp in cycles(edges.keys()):
                    members = set(comp)
                    name = "::".join(parent) or "crate"
                    witness = [w for (a, b), ws in sorted(edges.items()) if a in members and b in members for w in ws]
                    loops.append((os.path.normpath(crate), label, name, comp, witness))
    print("import loops: %d" % len(loops))
    for crate, label, parent, comp, witness in loops:
        print("  %s (%s), inside %s: %s" % (crate, label, parent, " <-> ".join(comp)))
        for a, b, where in witness:
            print("    %s -> %s   %s" % (a, b, where))
    problems += len(loops)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
