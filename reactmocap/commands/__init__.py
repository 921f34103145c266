"""CLI sub-commands. Each module defines ``register(subparsers)``; parsing only, no algorithms."""
