#!/usr/bin/env python3
"""Prints the studio's browser-measured latencies (web/tests/e2e/latency.test.mjs
writes build/browser-artifacts/latency.json) against the issue's goals, each
also as a ratio to the bare WebSocket round trip measured in the same run."""
import json
import sys

data = json.load(open(sys.argv[1]))
base = data["baseline_ws_round_trip_ms"]
goals = {"slider_to_redraw_ms": ("slider change -> map and histogram redrawn (tpad)", 50.0),
         "pointer_to_player_ms": ("pointer move -> position queued at the player", 10.0)}
print(f"Texel Studio latency ({data['browser']}, loopback, {data['measured_at']})")
print(f"  baseline: WebSocket round trip p50 {base['p50']:.2f} ms, p95 {base['p95']:.2f} ms (n {base['n']})")
for key, (label, goal) in goals.items():
    m = data[key]
    verdict = "met" if m["p95"] < goal else "NOT met"
    print(f"  {label}: p50 {m['p50']:.2f} ms, p95 {m['p95']:.2f} ms (n {m['n']}; "
          f"{m['p95'] / base['p95']:.1f}x baseline p95); goal p95 < {goal:g} ms: {verdict}")
