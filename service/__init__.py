"""The REST layer: a thin FastAPI shell over :mod:`solver` (ASGI app ``service.main:app``)."""
