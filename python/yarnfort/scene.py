# SPDX-License-Identifier: MIT
"""Scene building (in progress)."""
