"""Reproduction report: paper sections (paperNNN.py), shared types (types.py), rendering (render.py)."""
