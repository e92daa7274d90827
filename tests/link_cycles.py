"""Files that call each other in a circle, from the symbols of the built objects.

usage: link_cycles.py BUILD_DIR TARGET...   (objects as CMake links them: CMakeFiles/T.dir/link.txt)

For every object file of the targets (the ones the link line names, so objects left over from
files since moved do not count): the functions and data it defines and those it uses. File A depends on
file B when A uses a symbol B defines. Prints each cycle (a strongly connected set of two or
more files) and exits 1 when there is one, so that the layering stays a tree: a module calls
down into the modules below it, an adapter calls nothing above it.

The same is checked between modules (the folders: src/<domain>, calib, pipeline): module A
depends on module B when a file of A uses a symbol a file of B defines. A stage that joins
several domains lives above them (src/stages, src/run), so a domain never calls up into one
that calls it back. `--self-test` checks the checker on a made-up graph with an upward call."""
import collections
import os
import subprocess
import sys


def symbols(path):
    out = subprocess.run(["nm", path], capture_output=True, text=True, check=True).stdout
    defined, used = set(), set()
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[1] in "TDBR":
            defined.add(parts[2])
        elif len(parts) == 2 and parts[0] == "U":
            used.add(parts[1])
    return defined, used


def main(build, targets):
    defines, uses = {}, {}
    for target in targets:
        prefix = f"CMakeFiles/{target}.dir/"
        with open(os.path.join(build, prefix, "link.txt")) as f:
            objects = [w for w in f.read().split() if w.startswith(prefix) and w.endswith(".o")]
        for obj in objects:
            name = obj[len(prefix):-2]
            defines[name], uses[name] = symbols(os.path.join(build, obj))
    owner = {s: name for name, d in defines.items() for s in d}
    graph = {n: {owner[s] for s in u if s in owner and owner[s] != n} for n, u in uses.items()}

    file_cycles = report(graph, "files")
    module_cycles = report(modules_of(graph), "modules")
    return 1 if file_cycles or module_cycles else 0


def module(name):
    """src/field/stage.c -> field; calib/board.c -> calib; pipeline/cli.c -> pipeline."""
    parts = name.split("/")
    return parts[1] if parts[0] == "src" and len(parts) > 2 else parts[0]


def cycles_of(graph):
    """Strongly connected sets of two or more nodes (Tarjan's, iteratively)."""
    index, low, on, stack, cycles, counter = {}, {}, set(), [], [], [0]
    for start in graph:
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = counter[0]; counter[0] += 1
        stack.append(start); on.add(start)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = counter[0]; counter[0] += 1
                    stack.append(w); on.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                elif w in on:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop(); on.discard(w); comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    cycles.append(sorted(comp))
    return cycles


def report(graph, what):
    cycles = cycles_of(graph)
    for comp in cycles:
        edges = ", ".join(f"{a} -> {b}" for a in comp for b in sorted(graph[a]) if b in comp)
        print("cycle:", edges)
    print(f"{len(cycles)} cycles among {len(graph)} {what}")
    return len(cycles)


def self_test():
    """A layered graph passes; one upward call (capture -> attack -> capture) is caught."""
    layered = {"src/capture/ingest.c": {"src/core/json.c"},
               "src/attack/stage.c": {"src/capture/ingest.c"}, "src/core/json.c": set()}
    upward = dict(layered, **{"src/capture/dataset.c": {"src/attack/stage.c"}})
    clean, found = cycles_of(modules_of(layered)), cycles_of(modules_of(upward))
    print(f"self-test: layered {clean}, with the upward call {found}")
    return 0 if not clean and found == [["attack", "capture"]] else 1


def modules_of(graph):
    out = collections.defaultdict(set)
    for a, targets in graph.items():
        out.setdefault(module(a), set())
        for b in targets:
            if module(a) != module(b):
                out[module(a)].add(module(b))
    return dict(out)


if __name__ == "__main__":
    sys.exit(self_test() if sys.argv[1:] == ["--self-test"] else main(sys.argv[1], sys.argv[2:]))
