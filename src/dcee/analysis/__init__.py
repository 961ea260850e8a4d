"""Analysis: figures of one search and reports of campaigns (tables, intervals, tests)."""
