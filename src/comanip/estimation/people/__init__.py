"""People who are not the model: the models fitted to recorded people, and the endpoint rules and template
matching they are scored against."""
