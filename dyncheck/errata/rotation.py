"""Relative motion and angular velocity (2.2.50)–(2.2.63), Example 9's Euler angles, the tensor
forms of Euler's equations (2.2.64)–(2.2.69), exercises 23 and 30."""

from __future__ import annotations
