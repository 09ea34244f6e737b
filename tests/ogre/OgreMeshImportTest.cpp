// .mesh import tests come with the importer
