"""MJCF templates of the SEA snake and the pole scene, shipped as package data."""
