"""The whole pipeline as one call (:mod:`.analyze`), its warnings (:mod:`.diagnostics`) and text report (:mod:`.report`)."""
