"""The service's routes, one module per concern, as FastAPI routers (in OpenAPI order)."""

from . import diagnose, history, status

ROUTERS = (diagnose.router, history.router, status.router)
