"""GLSL shader files, shipped as package data."""
