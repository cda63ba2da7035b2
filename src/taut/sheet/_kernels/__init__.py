"""Compiled (numba) kernels of the sheet core: small-team FK, batched FK, branch following, and their dense linear algebra. Private."""
