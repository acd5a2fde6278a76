#!/usr/bin/env python3
"""Compares two output trees of scripts/run_example.sh: JSON and JSON lines by value (wall-clock
keys dropped, the base's renamed keys mapped), CSV, SVG and text line by line (wall-clock
figures masked). Usage: compare_outputs.py BASE_DIR NEW_DIR [RENAMED_KEYS.tsv]"""
import json
import os
import re
import sys

WALL_CLOCK_KEYS = {"elapsed_s", "planning_time_s"}
WALL_CLOCK_TEXT = re.compile(r"\b\d+(\.\d+)? ?(s|ms)\b")
SKIP_SUFFIXES = (".sqlite", ".sqlite-wal", ".sqlite-shm", ".sqlite-journal")


def load_renames(path):
    renames = {}
    if path and os.path.exists(path):
        for line in open(path, encoding="utf-8"):
            if line.strip() and not line.startswith("#"):
                old, new = line.rstrip("\n").split("\t")[:2]
                renames[old] = new
    return renames


def renamed(text, renames):
    for old, new in renames.items():
        text = text.replace(old, new)
    return text


def normalise(value, renames):
    if isinstance(value, dict):
        return {renamed(k, renames): normalise(v, renames) for k, v in value.items() if k not in WALL_CLOCK_KEYS}
    if isinstance(value, list):
        return [normalise(v, renames) for v in value]
    if isinstance(value, str):
        return renamed(value, renames)
    return value


def json_values(path, renames):
    text = open(path, encoding="utf-8").read()
    try:
        return [normalise(json.loads(text), renames)]
    except json.JSONDecodeError:
        pass
    try:
        return [normalise(json.loads(l), renames) for l in text.splitlines() if l.strip()]
    except json.JSONDecodeError:  # not JSON after all (e.g. a log with a .json name): as text
        return text_lines(path, renames)


def text_lines(path, renames):
    lines = []
    for line in open(path, encoding="utf-8", errors="replace").read().splitlines():
        lines.append(WALL_CLOCK_TEXT.sub("<t>", renamed(line, renames)))
    return lines


def first_difference(a, b, path="$"):
    """The JSON path of the first place where a and b differ, with both values there."""
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if a.get(k, "<absent>") != b.get(k, "<absent>"):
                return first_difference(a.get(k, "<absent>"), b.get(k, "<absent>"), f"{path}.{k}")
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for i, (x, y) in enumerate(zip(a, b)):
            if x != y:
                return first_difference(x, y, f"{path}[{i}]")
    return path, json.dumps(a)[:120], json.dumps(b)[:120]


def files(root):
    out = set()
    for d, _, names in os.walk(root):
        for n in names:
            if not n.endswith(SKIP_SUFFIXES):
                out.add(os.path.relpath(os.path.join(d, n), root))
    return out


def main():
    base, new = sys.argv[1], sys.argv[2]
    renames = load_renames(sys.argv[3] if len(sys.argv) > 3 else None)
    # Each run's output folder appears in its outputs (sources, messages): the same placeholder.
    renames = {**{os.path.abspath(base): "<OUT>", base: "<OUT>", os.path.abspath(new): "<OUT>", new: "<OUT>"}, **renames}
    base_files, new_files = files(base), files(new)
    problems = [f"only in the base: {f}" for f in sorted(base_files - new_files)]
    problems += [f"only in the new: {f}" for f in sorted(new_files - base_files)]
    for rel in sorted(base_files & new_files):
        b, n = os.path.join(base, rel), os.path.join(new, rel)
        json_like = rel.endswith((".json", ".jsonl", ".geojson"))
        read = json_values if json_like else text_lines
        vb, vn = read(b, renames), read(n, renames)
        if vb != vn:
            differing = [i for i, (x, y) in enumerate(zip(vb, vn)) if x != y]
            first = differing[0] if differing else min(len(vb), len(vn))
            where = ""
            if differing:
                path, x, y = first_difference(vb[first], vn[first])
                where = f"; first at {path}: {x} vs {y}"
            problems.append(f"{rel}: {len(differing)} item(s)/line(s) differ, from {first + 1} ({len(vb)} vs {len(vn)}){where}")
    for p in problems:
        print("compare_example:", p)
    print(f"compare_example: {len(base_files & new_files)} files compared, {len(problems)} difference(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
