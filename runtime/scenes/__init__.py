"""Scenes: TOML files with units, validated sections, pressure sources, the embedded default and hard scenes."""
