"""apexseal."""
