"""Stiffness models: gear mesh, thread contact, electric cylinder."""
