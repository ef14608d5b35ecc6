"""Design-code rules (EN 1991-2, EN 1990 Annex A2): limits, damping rules and cut-offs, each
with its clause, in one place."""
