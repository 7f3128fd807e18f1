#!/usr/bin/env python3
"""Writes a generated text into a file between its markers <!-- NAME:begin --> and <!-- NAME:end -->.

Usage: scripts/put-block.py FILE NAME TEXT_FILE
Every script that keeps a README figure generated (readme-figures.sh, jitter-bench.sh,
tests/pil/bench.sh) writes through this one helper.
"""
import sys

if len(sys.argv) != 4:
    sys.exit(__doc__.strip())
path, name, source = sys.argv[1:]
text = open(source).read().rstrip("\n")
content = open(path).read()
begin, end = f"<!-- {name}:begin -->", f"<!-- {name}:end -->"
if begin not in content or end not in content:
    sys.exit(f"put-block.py: {path} has no {begin} ... {end} block")
head, rest = content.split(begin, 1)
_, tail = rest.split(end, 1)
open(path, "w").write(head + begin + "\n" + text + "\n" + end + tail)
print(f"put-block.py: {name} written into {path}")
