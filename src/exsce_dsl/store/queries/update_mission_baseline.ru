# Set the baseline value and tolerance of a mission baseline oracle of a scenario.
#
# ?scenario   id      the scenario, by id
# ?metric     metric  the oracle's metric
# ?value      double  the new baseline value
# ?tolerance  double  the new tolerance
#
# As update_baseline, for the oracle of a mission metric (no oracle:robot).

DELETE { GRAPH ?g { ?usage oracle:value ?old_value . ?usage oracle:tolerance ?old_tolerance . } }
INSERT { GRAPH ?g { ?usage oracle:value ?value . ?usage oracle:tolerance ?tolerance . } }
WHERE {
  GRAPH ?g {
    ?oracle a exsce:oracle ;
            exsce:scenario ?scenario ;
            oracle:metric ?metric ;
            prov:qualifiedUsage ?usage .
    FILTER NOT EXISTS { ?oracle oracle:robot ?robot }
    ?usage oracle:type "baseline" .
    OPTIONAL { ?usage oracle:value ?old_value }
    OPTIONAL { ?usage oracle:tolerance ?old_tolerance }
  }
  FILTER(!CONTAINS(STR(?g), "revision="))
}
