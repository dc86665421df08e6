"""The spring-preload study: multiple-shooting NLP over the compiled hybrid integrator, checked by bisection."""
