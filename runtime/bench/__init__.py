"""Work-precision benchmark: what accuracy costs in time (issue: apexseal bench)."""
