"""What the tests share besides fixtures (those stay in ``tests/conftest.py``, where pytest finds
them).  Every test imports these the same way: ``from tests.support.bag_factory import write_bag``.

- ``paths``: the repository's folders (``ROOT``, ``EXAMPLES``, the method's published models
  in ``FIXTURES``).
- ``cli``: :func:`~tests.support.cli.run_exscec`, the real ``exscec`` console script in a subprocess.
- ``map_files``: :func:`~tests.support.map_files.write_map`, a map_server map with one occupied block.
- ``yard_spec``: two small yards as ``.exsce`` text: the signal and stack-run tests' (its robot
  type filled in per test) and the verify tests' two-robot patrol (``YARD_SPEC``).
- ``scenario_builders``: scenarios built by hand in the semantic model (scenario_c, large ones).
- ``bag_factory``: small bags in every format exsce reads, written with rosbags' writers.
- ``bag_surgery``: executor bags with what real recordings lose (cut short, silent, thinned topics).
- ``clock_bags``: executor bags restamped onto a simulated clock, with ``/clock``.
- ``bad_bags``: broken bags (killed recorders, cut copies, foreign headers) made from a small one.
- ``real_shapes``: bags of the shapes real robots and data sets record (Jackal, KITTI, ...).
- ``draft_references``: what a bag says of one robot, read with rosbags alone.
- ``reference_metrics``: the method's metrics computed by hand, the generated monitors' reference.
- ``prov_contract``: a compiled PROV document compared with the method's published models.
- ``campaign_samples``: one sample campaign's trials and shrinkings, as written to a store.
- ``store_servers``: real SPARQL servers (``oxigraph serve``, ``exscec serve``) as child processes.
- ``dask_cluster``: a real Dask cluster on 127.0.0.1, and a worker killed mid-task.
- ``ros1_graph``: a real ROS 1 graph (roscore, rosbag, nodes on Debian's Python).
- ``help_examples``: every ``exscec ... --help`` example, and the walk that runs a chapter of them.
- ``lsp_helpers``: the language server's end-to-end sessions, workspaces and waiting.
"""
