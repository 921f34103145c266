"""Measured tables (written by ``benchmarks/bench_athletics.py --tables``; do not edit)."""

from __future__ import annotations

from typing import Any

LEAP_TABLES: dict[str, Any] = {}
BROAD_TABLES: dict[str, Any] = {}
LANDING_DELTAS: dict[str, Any] = {}
SUPPORTED: dict[Any, Any] = {}
MEASURED_ON = ""
