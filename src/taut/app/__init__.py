"""``taut app``: a local web app to explore sheet teams, plans and cable robots.

A small ASGI server (Starlette, served by uvicorn) answers JSON requests from a plain
JavaScript page (charts and 3D views by Plotly.js, vendored in ``static/vendor``; no
build step, nothing fetched from the internet). The server only calls taut's public
analyses and loaders; :mod:`taut.app.server` lists the routes. Install with
``pip install 'taut[app]'``.
"""
