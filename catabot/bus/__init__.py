"""The bus: keys, messages and their codec, the lockstep clock and its participants, sessions.

Depends on nothing else in the project (but the root error), so a client of the bus in any
process, or a port to another language, needs only this package and docs/DESIGN.md.
"""
