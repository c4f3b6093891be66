# Set the baseline value and tolerance of a robot's baseline oracle of a scenario.
#
# ?scenario   id      the scenario, by id
# ?metric     metric  the oracle's metric
# ?robot      robot   the oracle's robot
# ?value      double  the new baseline value
# ?tolerance  double  the new tolerance
#
# Counterpart of the method's Listing 43: changes the usage of the
# scenario by the oracle whose oracle:type is "baseline".

DELETE { GRAPH ?g { ?usage oracle:value ?old_value . ?usage oracle:tolerance ?old_tolerance . } }
INSERT { GRAPH ?g { ?usage oracle:value ?value . ?usage oracle:tolerance ?tolerance . } }
WHERE {
  GRAPH ?g {
    ?oracle a exsce:oracle ;
            exsce:scenario ?scenario ;
            oracle:metric ?metric ;
            oracle:robot ?robot ;
            prov:qualifiedUsage ?usage .
    ?usage oracle:type "baseline" .
    OPTIONAL { ?usage oracle:value ?old_value }
    OPTIONAL { ?usage oracle:tolerance ?old_tolerance }
  }
  FILTER(!CONTAINS(STR(?g), "revision="))
}
