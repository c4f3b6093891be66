"""Work spread over processes: the Dask client that ingest, simulate and explore share."""
