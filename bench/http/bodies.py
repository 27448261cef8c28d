#!/usr/bin/env python3
"""bodies.py - request bodies of the HTTP benchmark, from the shape
fixtures: a signature request and an N-frame morph request.

usage: bodies.py OUTDIR FRAMES
"""
import json
import os
import sys

root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
with open(os.path.join(root, "tests", "fixtures", "shapes.json")) as f:
    pair = json.load(f)["pairs"][0]
out, frames = sys.argv[1], int(sys.argv[2])
with open(os.path.join(out, "signature.json"), "w") as f:
    json.dump({"curve": pair["a"]}, f)
with open(os.path.join(out, "morph.json"), "w") as f:
    json.dump({"from": pair["a"], "to": pair["b"], "frames": frames}, f)
print(pair["name"])
