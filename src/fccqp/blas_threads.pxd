# cython: language_level=3
cdef void enter() noexcept
cdef void leave() noexcept
