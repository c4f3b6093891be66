"""Work spread over processes: the process pool and the Dask client that ingest, simulate and explore
share (:mod:`~exsce_dsl.parallel.workers`, :mod:`~exsce_dsl.parallel.dask_client`)."""
