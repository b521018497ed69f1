"""Ensembles of rigid bodies: chunked batched flows, locally or on a dask cluster."""
