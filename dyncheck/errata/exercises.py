"""The results the exercises of §2.2 state (2–5, 18–20, 22, 25, 27, 28)."""

from __future__ import annotations
