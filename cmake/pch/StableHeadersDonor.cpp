// The source of a donor target of cmake/TreeLodStableHeaders.cmake: it compiles the precompiled
// header that the project's targets of its layer and kind reuse.
int main()
{
    return 0;
}
