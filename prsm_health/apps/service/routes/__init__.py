"""The service's routes, one module per concern, as FastAPI routers (in OpenAPI order); the
dashboard's pages and static files (not in the OpenAPI document) last."""

from . import assets, dashboard, diagnose, history, prognosis, status

ROUTERS = (
    diagnose.router,
    assets.router,
    history.router,
    prognosis.router,
    status.router,
    dashboard.router,
)
