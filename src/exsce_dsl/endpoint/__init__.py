"""``exscec serve``: the embedded store as a SPARQL 1.1 Protocol endpoint, an HTTP face over
:mod:`exsce_dsl.store` (beside :mod:`exsce_dsl.mcp_server`, the store's face for language models).

Starlette on uvicorn (h11) in front of a worker process that holds a pyoxigraph store:

* ``GET /query?query=...``, ``POST /query`` (``application/sparql-query`` or a
  form with ``query=``); ``default-graph-uri`` and ``named-graph-uri`` are
  honoured.  SELECT and ASK answer in SPARQL JSON, XML, CSV or TSV, CONSTRUCT
  and DESCRIBE in Turtle, N-Triples or RDF/XML, by the ``Accept`` header (or
  ``?format=json|xml|csv|tsv|ttl|nt``); JSON and Turtle when anything goes;
* ``POST /update`` (``application/sparql-update`` or a form with
  ``update=``): ``403`` unless the server was started with updates allowed,
  then ``401`` without ``Authorization: Bearer <token>`` (compared in
  constant time);
* ``/sparql`` takes both, like Virtuoso's and Neptune's endpoints;
* ``GET /store?graph=IRI`` (Graph Store Protocol, reading only): one graph,
  or the whole dataset as N-Quads or TriG without ``graph``;
* ``GET /``: a query page (no external resources).

Only one process may open an embedded store folder, so while the endpoint
runs its worker process holds the store (the HTTP process never opens it), and
the server says so in ``<store>.serve.json``
(:mod:`exsce_dsl.store.serve_info`: URL, pid, whether updates are allowed;
never the token) next to the folder.  :func:`exsce_dsl.store.open.open_store`
reads that file: other exscec commands on the same store go through the
endpoint (queries always; writes when updates are allowed and
``EXSCE_STORE_TOKEN`` holds the token) and otherwise fail with a message
naming the server and what to do.  The file is removed when the server stops
(Ctrl-C, SIGTERM: within a second, a running query killed).

Closed by default: SERVICE and LOAD reach no host unless ``--allow-federation``
names it; the ``Host`` header must name the server as bound (or a name given by
``--allowed-host``); pages of other origins are refused; a query is stopped at
its time limit and an answer at its size limit.

* :mod:`~exsce_dsl.endpoint.server` — the server, its start and its stop (uvicorn; why, there);
* :mod:`~exsce_dsl.endpoint.app` — the routes: each request made a job for the worker, or refused;
* :mod:`~exsce_dsl.endpoint.guard` — the doors: Host, Origin, framing, common headers;
* :mod:`~exsce_dsl.endpoint.evaluator` — the worker's handle: one job at a time, time limit, restart;
* :mod:`~exsce_dsl.endpoint.worker` — the worker process: the store, queries, answers in chunks;
* :mod:`~exsce_dsl.endpoint.protocol` — reading a request: parameters, bodies, HTTP errors;
* :mod:`~exsce_dsl.endpoint.formats` — answers' formats: content negotiation.
"""
