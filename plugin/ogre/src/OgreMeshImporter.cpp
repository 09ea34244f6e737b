// placeholder: .mesh import comes with the leaf-extraction move
