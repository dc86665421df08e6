"""Code generation: CasADi Functions and C code of the derived seal model.

* :mod:`.lower` - sympy expressions to CasADi SX;
* :mod:`.functions` - the model's Functions (``build_functions`` -> ``ModelFunctions``);
* :mod:`.codegen`, :mod:`.render` - CasADi C files and the rendered C templates (``templates/*.in.*``);
* :mod:`.manifest` - the record of inputs and outputs, staleness checks;
* :mod:`.generate` - the whole pipeline with stage timings;
* :mod:`.compile` - shared libraries in a content-keyed cache, ``compile_function``, interpreter fallback;
* :mod:`.compiler` - the C compiler: its flag sets (``FLAG_SETS``, ``register_flags``), finding and running it;
* :mod:`.variant` - model variants no manifest describes (a measurement's), on a record of their own;
* :mod:`.load` - ``load_functions``: SX and compiled Functions of a scene;
* ``default/`` - the committed artefacts of the default scene.
"""
