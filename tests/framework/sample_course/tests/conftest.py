pytest_plugins = ["geomlib.grading.plugin"]
