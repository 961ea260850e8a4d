"""Analysis: metrics and figures."""
