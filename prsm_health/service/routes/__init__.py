"""The service's routes, one module per concern, as FastAPI routers (in OpenAPI order)."""

from . import diagnose, history, prognosis, status

ROUTERS = (diagnose.router, history.router, prognosis.router, status.router)
